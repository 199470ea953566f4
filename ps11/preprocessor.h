// The C-style preprocessor Microsoft's shader assembler applies before assembling:
// #define (object- and function-like), #undef, #if/#ifdef/#ifndef/#elif/#else/#endif with
// integer expressions and defined(), #include "file" (relative to the including file,
// then -I directories), #error, and -D NAME[=VALUE] from the command line. Comments
// (// and /* */) are removed here; ';' comments are left for the lexer.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ps11/diagnostics.h"

namespace ps11 {

struct PreprocessOptions {
    std::vector<std::pair<std::string, std::string>> defines;  // -D NAME[=VALUE] (VALUE "1" if absent)
    std::vector<std::string> includeDirs;                       // -I DIR, searched in order
    // Reads a file for #include; defaults to the filesystem. Returns nullopt if unreadable.
    std::function<std::optional<std::string>(const std::string& path)> readFile;
    int maxIncludeDepth = 64;
};

// One line of preprocessed output with where each byte came from.
struct PreprocessedLine {
    std::string text;
    uint32_t fileId = 0;            // Diagnostics file id of the line's origin
    uint32_t line = 0;              // 1-based line in that file
    std::vector<uint32_t> columns;  // 1-based original column of each byte of text
                                    // (bytes produced by a macro map to the macro name's column)
    SourceLoc locAt(size_t byteIndex) const;
};

// Preprocesses `source`, whose name is `fileName` (registered in diags; includes are
// resolved relative to its directory). Directives produce no output lines; every other
// line of the source appears in order (blank when skipped by #if). Lines joined by a
// backslash-newline come out as one line numbered by its first physical line. Errors (P10xx,
// see docs/diagnostics.md) are reported to diags; processing continues where it can.
std::vector<PreprocessedLine> preprocess(std::string_view source, const std::string& fileName,
                                         const PreprocessOptions& options, Diagnostics& diags);

}  // namespace ps11
