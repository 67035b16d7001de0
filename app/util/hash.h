// hash.h — FNV-1a 64, the one hash of files and data (scene fingerprints of checkpoints and the bench's
// reference cache, checkpoint checksums, the renderer's check that meshes did not change).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace caustica {

// FNV-1a, 64-bit. Chain calls by passing the previous hash as `hash`.
constexpr std::uint64_t kFnv1a64Offset = 0xcbf29ce484222325ull;
std::uint64_t fnv1a64(const void* data, std::size_t size, std::uint64_t hash = kFnv1a64Offset);
std::uint64_t fnv1a64(const std::string& text, std::uint64_t hash = kFnv1a64Offset);
std::string hex64(std::uint64_t value);  // 16 lower-case hex digits

}  // namespace caustica
