// Shared pieces of the ps11 command line: file reading and writing with clear errors,
// the -D/-I options, and locating the project's own data (shader corpus, golden files).
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ps11/assembler.h"
#include "ps11/diagnostics.h"

namespace ps11::cli {

// Exit codes (DESIGN.md): 0 success, 1 user error, 2 usage error.
enum ExitCode : int { kOk = 0, kUserError = 1, kUsage = 2 };

// Reads a whole file ("-" = standard input). On failure prints "ps11: cannot read FILE: why"
// and returns nullopt.
std::optional<std::string> readFile(const std::string& path);
// Writes a whole file; prints an error and returns false on failure.
bool writeFile(const std::string& path, const std::string& bytes);

// Consumes -D NAME[=VALUE], -DNAME, -I DIR, -IDIR at args[i]; returns true if it did.
// Sets `error` for a -D/-I without argument.
bool takePreprocessorOption(const std::vector<std::string>& args, size_t& i, PreprocessOptions& pp,
                            std::string& error);

// The project's source directory (for the built-in corpus), or "" if not found.
std::string projectDir();

// Every *.psh under dir, sorted.
std::vector<std::string> listFiles(const std::string& dir, const std::string& extension);

// "unknown option '--hx'; did you mean '--hex'?" (the argument cut to a readable length; the
// suggestion from the command's options, ps11/suggest.h).
std::string unknownOption(std::string_view arg, std::initializer_list<std::string_view> options);

std::string hexWords(const std::vector<uint32_t>& tokens, size_t perLine = 8);

// A finite float (an optional leading '+'), nothing else in the string.
std::optional<float> parseFloat(const std::string& s);
// "0x" and 1-8 hex digits.
std::optional<uint32_t> parseHexWord(const std::string& s);
// "x,y,z,w" with 1-4 components (missing ones 0), or with `allowWord` one 0xAARRGGBB colour
// word (r g b a in [0, 1]).
std::optional<std::array<float, 4>> parseVector(const std::string& s, bool allowWord);
// "lo,hi": two finite floats with lo <= hi.
std::optional<std::pair<float, float>> parseRange(const std::string& s);
// The sides a command's --size takes: kMaxSizeSide at most (every command that renders a frame),
// and at least kMinGlareFrameSide where the commands run whole glare frames (demo, bench).
constexpr uint32_t kMaxSizeSide = 8192;
constexpr uint32_t kMinGlareFrameSide = 8;
// "WxH" (or "WXH") with both sides in minSide..maxSide; false for anything else.
bool parseSize(const std::string& text, uint32_t& width, uint32_t& height, uint32_t maxSide = kMaxSizeSide,
               uint32_t minSide = 1);
// What parseSize takes, for usage errors: "WxH with sides 1..8192".
std::string sizeRule(uint32_t maxSide = kMaxSizeSide, uint32_t minSide = 1);
// A whole decimal number in lo..hi; false for anything else (signs, spaces, overflow).
bool parseCount(const std::string& text, int lo, int hi, int& value);

}  // namespace ps11::cli
