// Diagnostics: collection and the `file:line:col: error CODE: message` format shared by
// every stage.
#include "ps11/diagnostics.h"

namespace ps11 {

uint32_t Diagnostics::addFile(std::string name) {
    for (size_t i = 0; i < m_files.size(); ++i)
        if (m_files[i] == name) return uint32_t(i);
    m_files.push_back(std::move(name));
    return uint32_t(m_files.size() - 1);
}

const std::string& Diagnostics::fileName(uint32_t id) const { return id < m_files.size() ? m_files[id] : m_files[0]; }

void Diagnostics::error(std::string_view code, SourceLoc loc, std::string message) {
    m_diags.push_back({Severity::Error, std::string(code), loc, std::move(message)});
    ++m_errorCount;
}

void Diagnostics::warning(std::string_view code, SourceLoc loc, std::string message) {
    m_diags.push_back({Severity::Warning, std::string(code), loc, std::move(message)});
}

void Diagnostics::note(SourceLoc loc, std::string message) {
    m_diags.push_back({Severity::Note, std::string(), loc, std::move(message)});
}

bool Diagnostics::has(std::string_view code) const {
    for (const Diagnostic& d : m_diags)
        if (d.severity == Severity::Error && d.code == code) return true;
    return false;
}

void Diagnostics::clear() {
    m_diags.clear();
    m_errorCount = 0;
}

std::string Diagnostics::format(const Diagnostic& d) const {
    std::string out = fileName(d.loc.fileId);
    if (d.loc.tokenIndex >= 0) {
        out += ": token " + std::to_string(d.loc.tokenIndex);
    } else if (d.loc.line > 0) {
        out += ":" + std::to_string(d.loc.line);
        if (d.loc.col > 0) out += ":" + std::to_string(d.loc.col);
    }
    switch (d.severity) {
        case Severity::Error: out += ": error "; break;
        case Severity::Warning: out += ": warning "; break;
        case Severity::Note: out += ": note"; break;
    }
    out += d.code;
    out += ": ";
    out += d.message;
    return out;
}

std::string excerpt(std::string_view text, size_t maxBytes) {
    size_t cut = text.size();
    if (cut > maxBytes) {
        cut = maxBytes;
        // Back up to the start of a UTF-8 character so the cut never splits one.
        while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
    }
    std::string out;
    out.reserve(cut + 8);
    for (char c : text.substr(0, cut)) {
        const unsigned char u = static_cast<unsigned char>(c);
        if (u < 0x20 || u == 0x7f) {
            static const char* hex = "0123456789abcdef";
            out += "\\x";
            out += hex[u >> 4];
            out += hex[u & 15];
        } else {
            out += c;
        }
    }
    if (cut < text.size()) out += "…";
    return out;
}

std::string quote(std::string_view text, size_t maxBytes) { return "'" + excerpt(text, maxBytes) + "'"; }

std::string Diagnostics::formatAll() const {
    std::string out;
    for (const Diagnostic& d : m_diags) {
        out += format(d);
        out += '\n';
    }
    return out;
}

}  // namespace ps11
