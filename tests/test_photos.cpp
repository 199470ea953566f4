// The sample photographs' manifest and the image files of a folder (glare/photos.h).
#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <string>

#include "glare/photos.h"
#include "tests/temp_files.h"

using namespace glare;
using test_files::TempDir;

namespace {

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

}  // namespace

TEST_CASE("photos: the manifest parses into pictures with their licences", "[photos]") {
    const std::string text =
        "# Sample photographs fetched by tools/sample-images.sh; read by glare/photos.h.\n"
        "# path\tpackage\tlicence\tdescription\n"
        "psychtoolbox-3-common/Desk.exr\tpsychtoolbox-3-common 3.0.18.12.dfsg1-1.1\tBSD-3-Clause\tan open book\n"
        "\n"
        "blender-data/city.exr\tblender-data 3.4.1+dfsg-2\tCC0-1.0\t\r\n";
    std::string error;
    const auto photos = parsePhotoManifest(text, "/cache", "images.tsv", error);
    REQUIRE(photos);
    REQUIRE(photos->size() == 2);
    CHECK((*photos)[0].path == "/cache/psychtoolbox-3-common/Desk.exr");
    CHECK((*photos)[0].name == "psychtoolbox-3-common/Desk.exr");
    CHECK((*photos)[0].package == "psychtoolbox-3-common 3.0.18.12.dfsg1-1.1");
    CHECK((*photos)[0].licence == "BSD-3-Clause");
    CHECK((*photos)[0].description == "an open book");
    CHECK((*photos)[1].licence == "CC0-1.0");
    CHECK((*photos)[1].description.empty());  // an empty description is allowed; the \r of CRLF is not kept

    const auto refuse = [&](const std::string& line) {
        CHECK_FALSE(parsePhotoManifest("# header\n" + line + "\n", "/cache", "images.tsv", error));
        return error;
    };
    CHECK(refuse("a.exr\tpkg\tCC0-1.0") ==
          "images.tsv:2: expected 4 fields separated by tabs (path, package, licence, description), found 3");
    CHECK(refuse("a.exr pkg CC0-1.0 words") ==
          "images.tsv:2: expected 4 fields separated by tabs (path, package, licence, description), found 1");
    CHECK(refuse("\tpkg\tCC0-1.0\tx") == "images.tsv:2: empty path");
    CHECK(refuse("a.exr\t\tCC0-1.0\tx") == "images.tsv:2: empty package for a.exr");
    CHECK(refuse("a.exr\tpkg\t\tx") == "images.tsv:2: empty licence for a.exr");
    CHECK(refuse("/etc/a.exr\tpkg\tCC0-1.0\tx") ==
          "images.tsv:2: the path /etc/a.exr is absolute; paths are relative to the folder");
    CHECK(refuse("p/../../a.exr\tpkg\tCC0-1.0\tx") == "images.tsv:2: the path p/../../a.exr leaves the folder");
    CHECK(parsePhotoManifest("", "/cache", "images.tsv", error)->empty());
}

TEST_CASE("photos: the cache folder, its manifest and missing pictures", "[photos]") {
    TempDir dir("ps11_photos_");
    std::string error;
    const std::string cache = dir.file("cache");
    CHECK_FALSE(listPhotos(error, cache));
    CHECK(error.rfind(cache + ": no sample photographs; tools/sample-images.sh fetches them", 0) == 0);
    std::filesystem::create_directories(cache + "/pkg");
    CHECK_FALSE(listPhotos(error, cache));
    CHECK(error.rfind(cache + "/images.tsv: no manifest of sample photographs; tools/sample-images.sh", 0) == 0);
    write(cache + "/images.tsv", "pkg/a.exr\tpkg 1.0\tCC0-1.0\tone\npkg/b.hdr\tpkg 1.0\tBSD-3-Clause\ttwo\n");
    write(cache + "/pkg/a.exr", "x");
    CHECK_FALSE(listPhotos(error, cache));
    CHECK(error == cache + "/pkg/b.hdr: listed in " + cache + "/images.tsv but missing; run tools/sample-images.sh again");
    write(cache + "/pkg/b.hdr", "x");
    const auto photos = listPhotos(error, cache);
    REQUIRE(photos);
    REQUIRE(photos->size() == 2);
    CHECK((*photos)[1].path == cache + "/pkg/b.hdr");
    CHECK((*photos)[1].licence == "BSD-3-Clause");

    // PS11_IMAGES chooses the folder.
    const char* old = std::getenv("PS11_IMAGES");
    const std::string saved = old ? old : "";
    setenv("PS11_IMAGES", cache.c_str(), 1);
    CHECK(photoCacheDir() == cache);
    const auto fromEnv = listPhotos(error);
    CHECK((fromEnv && fromEnv->size() == 2));
    if (old)
        setenv("PS11_IMAGES", saved.c_str(), 1);
    else
        unsetenv("PS11_IMAGES");
}

TEST_CASE("photos: the image files of a folder, sorted", "[photos]") {
    TempDir dir("ps11_photos_");
    std::string error;
    for (const char* name : {"b.png", "A.EXR", "c.hdr", "notes.txt", "d.png.bak"}) write(dir.file(name), "x");
    std::filesystem::create_directories(dir.file("sub.png"));
    const auto files = imageFilesIn(dir.path.string(), error);
    REQUIRE(files);
    CHECK(*files == std::vector<std::string>{dir.file("A.EXR"), dir.file("b.png"), dir.file("c.hdr")});
    CHECK_FALSE(imageFilesIn(dir.file("none"), error));
    CHECK(error.rfind(dir.file("none") + ": cannot read the folder: ", 0) == 0);
    CHECK(imageFilesIn(dir.file("sub.png"), error)->empty());
}
