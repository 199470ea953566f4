// The sample photographs' cache and manifest, and the image files of a folder (glare/photos.h).
#include "glare/photos.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

namespace glare {

namespace fs = std::filesystem;

std::string photoFetchHint(const std::string& dir) {
    return "tools/sample-images.sh fetches them from Debian packages (psychtoolbox-3-common, blender-data) into " +
           (dir.empty() ? std::string("~/.cache/ps11/images") : dir) + " ($PS11_IMAGES chooses another folder)";
}

std::string photoCacheDir() {
    if (const char* env = std::getenv("PS11_IMAGES"); env && *env) return env;
    if (const char* home = std::getenv("HOME"); home && *home) return (fs::path(home) / ".cache/ps11/images").string();
    return "";
}

std::optional<std::vector<Photo>> parsePhotoManifest(const std::string& text, const std::string& dir,
                                                     const std::string& name, std::string& error) {
    std::vector<Photo> photos;
    std::istringstream in(text);
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty() || line[0] == '#') continue;
        const auto fail = [&](const std::string& what) {
            error = name + ":" + std::to_string(number) + ": " + what;
            return std::nullopt;
        };
        std::vector<std::string> fields;
        for (size_t start = 0;;) {
            const size_t tab = line.find('\t', start);
            fields.push_back(line.substr(start, tab == std::string::npos ? std::string::npos : tab - start));
            if (tab == std::string::npos) break;
            start = tab + 1;
        }
        if (fields.size() != 4)
            return fail("expected 4 fields separated by tabs (path, package, licence, description), found " +
                        std::to_string(fields.size()));
        Photo p{"", fields[0], fields[1], fields[2], fields[3]};
        if (p.name.empty()) return fail("empty path");
        if (p.package.empty()) return fail("empty package for " + p.name);
        if (p.licence.empty()) return fail("empty licence for " + p.name);
        const fs::path relative(p.name);
        if (relative.is_absolute()) return fail("the path " + p.name + " is absolute; paths are relative to the folder");
        for (const fs::path& part : relative)
            if (part == "..") return fail("the path " + p.name + " leaves the folder");
        p.path = (fs::path(dir) / relative).string();
        photos.push_back(std::move(p));
    }
    return photos;
}

std::optional<std::vector<Photo>> listPhotos(std::string& error, const std::string& dirArg) {
    const std::string dir = dirArg.empty() ? photoCacheDir() : dirArg;
    if (dir.empty()) {
        error = "no folder for the sample photographs: neither PS11_IMAGES nor HOME is set; " + photoFetchHint(dir);
        return std::nullopt;
    }
    const std::string manifest = (fs::path(dir) / kPhotoManifest).string();
    std::ifstream in(manifest, std::ios::binary);
    if (!in) {
        std::error_code ec;
        error = fs::is_directory(dir, ec) ? manifest + ": no manifest of sample photographs; " + photoFetchHint(dir)
                                          : dir + ": no sample photographs; " + photoFetchHint(dir);
        return std::nullopt;
    }
    std::ostringstream text;
    text << in.rdbuf();
    std::optional<std::vector<Photo>> photos = parsePhotoManifest(text.str(), dir, manifest, error);
    if (!photos) return std::nullopt;
    for (const Photo& p : *photos) {
        std::error_code ec;
        if (!fs::is_regular_file(p.path, ec)) {
            error = p.path + ": listed in " + manifest + " but missing; run tools/sample-images.sh again";
            return std::nullopt;
        }
    }
    return photos;
}

std::optional<std::vector<std::string>> imageFilesIn(const std::string& dir, std::string& error) {
    std::vector<std::string> files;
    std::error_code ec;
    fs::directory_iterator it(dir, ec);
    if (ec) {
        error = dir + ": cannot read the folder: " + ec.message();
        return std::nullopt;
    }
    for (; it != fs::directory_iterator(); it.increment(ec)) {
        if (ec) break;
        std::string ext = it->path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        std::error_code typeError;
        if ((ext == ".png" || ext == ".hdr" || ext == ".exr") && it->is_regular_file(typeError))
            files.push_back(it->path().string());
    }
    if (ec) {
        error = dir + ": cannot read the folder: " + ec.message();
        return std::nullopt;
    }
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace glare
