// Diagnostics: collected, never thrown. Every message carries a code (P1xxx parse,
// P2xxx validate, P3xxx decode, E4xxx device, G5xxx graph) and a place: file, line and
// column for text, or the token index for binary input.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace ps11 {

// A place in a source file. fileId indexes Diagnostics::files(); line and col are 1-based,
// 0 when unknown. tokenIndex >= 0 marks a place in a binary token stream instead.
struct SourceLoc {
    uint32_t fileId = 0;
    uint32_t line = 0;
    uint32_t col = 0;
    int32_t tokenIndex = -1;
};

enum class Severity : uint8_t { Error, Warning, Note };

struct Diagnostic {
    Severity severity = Severity::Error;
    std::string code;  // e.g. "P2003"
    SourceLoc loc;
    std::string message;
};

class Diagnostics {
public:
    // Registers a file name and returns its id (the same id for the same name).
    uint32_t addFile(std::string name);
    const std::string& fileName(uint32_t id) const;

    void error(std::string_view code, SourceLoc loc, std::string message);
    void warning(std::string_view code, SourceLoc loc, std::string message);
    void note(SourceLoc loc, std::string message);

    bool hasErrors() const { return m_errorCount > 0; }
    size_t errorCount() const { return m_errorCount; }
    const std::vector<Diagnostic>& all() const { return m_diags; }
    // True if an error with this code was reported.
    bool has(std::string_view code) const;
    void clear();

    // "file:line:col: error P2003: message" (or "file: token 5 (0x...): ..." for binary).
    std::string format(const Diagnostic& d) const;
    std::string formatAll() const;

private:
    std::vector<std::string> m_files{"<input>"};
    std::vector<Diagnostic> m_diags;
    size_t m_errorCount = 0;
};

// User text echoed in a message is cut to this many bytes (then "…"), so a 10 MB line or
// identifier still gives a one-line diagnostic.
inline constexpr size_t kExcerptBytes = 48;

// User text for a message: at most kExcerptBytes bytes (cut at a UTF-8 character boundary and
// followed by "…"), control bytes written as \xNN. Every stage quotes input through this.
std::string excerpt(std::string_view text, size_t maxBytes = kExcerptBytes);
// excerpt() between single quotes: 'text'.
std::string quote(std::string_view text, size_t maxBytes = kExcerptBytes);

}  // namespace ps11
