// Command-line plumbing shared by the ps11 subcommands: file I/O with messages that name
// the file and the reason, preprocessor options, and the built-in data locations.
#include "tools/cli_util.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>

#include "ps11/suggest.h"
#include "ps11/testfile.h"

namespace ps11::cli {

std::string unknownOption(std::string_view arg, std::initializer_list<std::string_view> options) {
    return "unknown option " + quote(arg) + didYouMean(arg, options);
}

std::optional<std::string> readFile(const std::string& path) {
    if (path == "-") {
        std::ostringstream ss;
        ss << std::cin.rdbuf();
        return ss.str();
    }
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        std::cerr << "ps11: cannot read " << path << ": is a directory\n";
        return std::nullopt;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        std::cerr << "ps11: cannot read " << path << ": " << std::strerror(errno) << "\n";
        return std::nullopt;
    }
    std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) {
        std::cerr << "ps11: cannot read " << path << ": read error\n";
        return std::nullopt;
    }
    return data;
}

bool writeFile(const std::string& path, const std::string& bytes) {
    if (path == "-") {
        std::cout.write(bytes.data(), std::streamsize(bytes.size()));
        return bool(std::cout);
    }
    // Write to a temporary beside the target and rename, so a failed write never leaves a
    // half-written output in place of an older good one.
    std::string tmp = path + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) {
            std::cerr << "ps11: cannot write " << path << ": " << std::strerror(errno) << "\n";
            return false;
        }
        out.write(bytes.data(), std::streamsize(bytes.size()));
        out.close();
        if (!out) {
            std::cerr << "ps11: cannot write " << path << ": write error\n";
            std::remove(tmp.c_str());
            return false;
        }
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        std::cerr << "ps11: cannot write " << path << ": " << ec.message() << "\n";
        std::remove(tmp.c_str());
        return false;
    }
    return true;
}

bool takePreprocessorOption(const std::vector<std::string>& args, size_t& i, PreprocessOptions& pp,
                            std::string& error) {
    const std::string& a = args[i];
    if (a.rfind("-D", 0) != 0 && a.rfind("-I", 0) != 0) return false;
    std::string value = a.substr(2);
    if (value.empty()) {
        if (i + 1 >= args.size()) {
            error = a + " needs an argument";
            return true;
        }
        value = args[++i];
    }
    if (a[1] == 'D') {
        size_t eq = value.find('=');
        std::string name = value.substr(0, eq);
        if (name.empty()) {
            error = "-D needs a macro name";
            return true;
        }
        pp.defines.emplace_back(name, eq == std::string::npos ? "1" : value.substr(eq + 1));
    } else {
        pp.includeDirs.push_back(value);
    }
    return true;
}

std::string projectDir() {
    namespace fs = std::filesystem;
    std::error_code ec;
#ifdef PS11_SOURCE_DIR
    if (fs::exists(fs::path(PS11_SOURCE_DIR) / "tests" / "shaders", ec)) return PS11_SOURCE_DIR;
#endif
    if (fs::exists(fs::path("tests") / "shaders", ec)) return fs::current_path(ec).string();
    return "";
}

std::vector<std::string> listFiles(const std::string& dir, const std::string& extension) {
    namespace fs = std::filesystem;
    std::vector<std::string> out;
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return out;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
        if (it->is_regular_file(ec) && it->path().extension() == extension) out.push_back(it->path().string());
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::string hexWords(const std::vector<uint32_t>& tokens, size_t perLine) {
    std::string out;
    char buf[16];
    for (size_t i = 0; i < tokens.size(); ++i) {
        std::snprintf(buf, sizeof buf, "0x%08x", tokens[i]);
        out += buf;
        out += (i + 1 == tokens.size() || (i + 1) % perLine == 0) ? '\n' : ' ';
    }
    return out;
}

std::optional<float> parseFloat(const std::string& s) {
    if (s.empty()) return std::nullopt;
    const char* begin = s.data() + (s[0] == '+' ? 1 : 0);
    const char* end = s.data() + s.size();
    float v = 0;
    auto [ptr, ec] = std::from_chars(begin, end, v);
    if (ec != std::errc() || ptr != end || !std::isfinite(v)) return std::nullopt;
    return v;
}

std::optional<uint32_t> parseHexWord(const std::string& s) {
    if (s.size() < 3 || s.size() > 10 || s[0] != '0' || (s[1] != 'x' && s[1] != 'X')) return std::nullopt;
    uint32_t v = 0;
    auto [ptr, ec] = std::from_chars(s.data() + 2, s.data() + s.size(), v, 16);
    if (ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
    return v;
}

std::optional<std::array<float, 4>> parseVector(const std::string& s, bool allowWord) {
    if (allowWord)
        if (std::optional<uint32_t> w = parseHexWord(s))
            return Color::fromArgb(*w).rgba;
    std::array<float, 4> v{0, 0, 0, 0};
    size_t start = 0;
    for (size_t c = 0;; ++c) {
        if (c == 4) return std::nullopt;
        size_t comma = s.find(',', start);
        std::optional<float> f = parseFloat(s.substr(start, comma == std::string::npos ? comma : comma - start));
        if (!f) return std::nullopt;
        v[c] = *f;
        if (comma == std::string::npos) return v;
        start = comma + 1;
    }
}

std::optional<std::pair<float, float>> parseRange(const std::string& s) {
    const size_t comma = s.find(',');
    if (comma == std::string::npos) return std::nullopt;
    std::optional<float> lo = parseFloat(s.substr(0, comma)), hi = parseFloat(s.substr(comma + 1));
    if (!lo || !hi || *lo > *hi) return std::nullopt;
    return std::pair<float, float>{*lo, *hi};
}

bool parseSize(const std::string& text, uint32_t& width, uint32_t& height, uint32_t maxSide, uint32_t minSide) {
    unsigned long a = 0, b = 0;
    char x = 0, tail = 0;
    if (std::sscanf(text.c_str(), "%lu%c%lu%c", &a, &x, &b, &tail) != 3 || (x != 'x' && x != 'X')) return false;
    if (text.find_first_of("+- ") != std::string::npos) return false;
    if (a < std::max(minSide, 1u) || b < std::max(minSide, 1u) || a > maxSide || b > maxSide) return false;
    width = uint32_t(a);
    height = uint32_t(b);
    return true;
}

std::string sizeRule(uint32_t maxSide, uint32_t minSide) {
    return "WxH with sides " + std::to_string(std::max(minSide, 1u)) + ".." + std::to_string(maxSide);
}

bool parseCount(const std::string& text, int lo, int hi, int& value) {
    if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos) return false;
    const long v = std::stol(text);
    if (v < lo || v > hi) return false;
    value = int(v);
    return true;
}

}  // namespace ps11::cli
