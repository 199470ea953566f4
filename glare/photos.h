// Real photographs as glare inputs (docs/images.md "Sample photographs"): the folder that
// tools/sample-images.sh fills from Debian packages, outside the repository and never committed, and
// its manifest (images.tsv: path, source package, licence, description). Also the image files of any
// folder, for `--in DIR`.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace glare {

// One picture of the manifest.
struct Photo {
    std::string path;         // the file: the cache folder joined with the manifest's relative path
    std::string name;         // the manifest's relative path, e.g. "blender-data/city.exr"
    std::string package;      // the Debian package it came from, with its version
    std::string licence;      // SPDX identifier, e.g. "CC0-1.0", "BSD-3-Clause"
    std::string description;  // what it shows, its size and compression
};

// The manifest's file name in the cache folder.
inline constexpr const char* kPhotoManifest = "images.tsv";

// What to run to get the photographs, for messages: "tools/sample-images.sh (fetches ... into DIR)".
std::string photoFetchHint(const std::string& dir);

// The cache folder: $PS11_IMAGES when set and not empty, else $HOME/.cache/ps11/images ("" when
// neither HOME nor PS11_IMAGES is set). It may not exist.
std::string photoCacheDir();

// Parses a manifest's text: one picture a line, four fields separated by tabs (path relative to the
// cache folder, package, licence, description); empty lines and lines starting with '#' are skipped.
// `dir` is joined to each path; `name` stands for the file in messages. nullopt with error =
// "NAME:LINE: what is wrong" for a line without four fields, an empty path, package or licence, or a
// path that is absolute or climbs out of the folder ("..").
std::optional<std::vector<Photo>> parsePhotoManifest(const std::string& text, const std::string& dir,
                                                     const std::string& name, std::string& error);

// The photographs of the cache folder `dir` (photoCacheDir() when empty), in manifest order. nullopt
// with error when the folder or its manifest is missing (the message says how to fetch them), the
// manifest does not parse, or a picture it lists is missing.
std::optional<std::vector<Photo>> listPhotos(std::string& error, const std::string& dir = "");

// The image files directly in a folder (regular files, or links to them, named *.png, *.hdr or *.exr in
// any case), sorted by name (bytewise). nullopt with error = "DIR: ..." when the folder cannot be
// read; an empty list when it holds none.
std::optional<std::vector<std::string>> imageFilesIn(const std::string& dir, std::string& error);

}  // namespace glare
