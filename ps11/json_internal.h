// The JSON the commands and libraries print (`ps11 check --json`, `ps11 glare --report --json`,
// `ps11 hardware --json`, ...): built as nlohmann::ordered_json values (keys in the order they are
// set), so escaping, NaN and nesting are right by construction. Internal: included by .cpp files
// only (ps11core, glare, the ps11 command), never by a public header, so the installed libraries
// need no nlohmann-json.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <nlohmann/json.hpp>

namespace ps11::json {

using Json = nlohmann::ordered_json;

// A JSON number for a double: null where it is not finite (JSON has no NaN or Inf), an integer
// where the value is one (as printf's %g writes it: `1`, not `1.0`), else the double.
inline Json number(double v) {
    if (!std::isfinite(v)) return Json(nullptr);
    if (v == std::trunc(v) && std::fabs(v) < 9007199254740992.0) return Json(static_cast<long long>(v));
    return Json(v);
}

// The number printf writes with `format` (one double conversion, e.g. "%.3f" or "%g"), read back:
// the value a user saw in the old hand-written output, with the same digits. Null where not finite.
inline Json rounded(double v, const char* format) {
    if (!std::isfinite(v)) return Json(nullptr);
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return number(std::strtod(buf, nullptr));
}

// One value as text. Strings that are not valid UTF-8 (a Latin-1 file name) get U+FFFD for each
// bad byte instead of an exception. Containers nested less than `lineDepth` deep that hold a
// container are written one element per line, indented by `indent` per level; all others on one
// line, with ", " and ": " between items (lineDepth 0: everything on one line).
inline std::string dump(const Json& j, int lineDepth = 0, int indent = 2, int depth = 0) {
    const bool container = j.is_object() || j.is_array();
    if (!container || j.empty()) return j.dump(-1, ' ', false, Json::error_handler_t::replace);
    bool nested = false;
    for (const Json& v : j) nested = nested || v.is_object() || v.is_array();
    const bool lines = nested && depth < lineDepth;
    const std::string inner = lines ? "\n" + std::string(size_t(indent * (depth + 1)), ' ') : "";
    const std::string outer = lines ? "\n" + std::string(size_t(indent * depth), ' ') : "";
    std::string out(1, j.is_object() ? '{' : '[');
    bool first = true;
    for (auto it = j.begin(); it != j.end(); ++it) {
        out += first ? inner : "," + (lines ? inner : std::string(" "));
        first = false;
        if (j.is_object()) out += Json(it.key()).dump(-1, ' ', false, Json::error_handler_t::replace) + ": ";
        out += dump(it.value(), lineDepth, indent, depth + 1);
    }
    return out + outer + (j.is_object() ? '}' : ']');
}

// The library's own compact form (no spaces), with the same UTF-8 replacement.
inline std::string dumpCompact(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace); }

}  // namespace ps11::json
