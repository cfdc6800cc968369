// Shared by the libFuzzer targets: the input is written to a per-process file
// (the readers take paths, as users give them), and every exception other than a
// clean InputError is a bug: it escapes and libFuzzer reports it.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "wheelins/nav/types.hpp"

namespace wheelins::fuzz {

inline std::filesystem::path scratch_file(const char* name) {
  return std::filesystem::temp_directory_path() /
         ("wheelins-fuzz-" + std::to_string(::getpid()) + "-" + name);
}

inline void write_bytes(const std::filesystem::path& file, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(file.c_str(), "wb");
  if (!f) __builtin_trap();
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
}

}  // namespace wheelins::fuzz
