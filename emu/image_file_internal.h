// What the image readers (emu/image_file.cpp, image_hdr.cpp, image_exr.cpp) share: opening a file
// with the same errors, and bytes shown in messages.
#pragma once

#include <sys/stat.h>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

namespace emu::image_detail {

using FilePtr = std::unique_ptr<FILE, int (*)(FILE*)>;

// Opens `path` for reading and stats it. Null with `error` = "PATH: cannot open: <strerror>" or
// "PATH: cannot read: Is a directory"; `st` is filled (zeroed when fstat fails).
FilePtr openImageFile(const std::string& path, struct stat& st, std::string& error);

// "89 50 4e 47": bytes in hex for messages.
std::string hexBytes(const uint8_t* p, size_t n);

}  // namespace emu::image_detail
