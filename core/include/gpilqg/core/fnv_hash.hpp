#pragma once
/// @file fnv_hash.hpp
/// The 64-bit FNV-1a hash (Fowler, Noll, Vo): h = (h xor byte) * 1099511628211 over the bytes, from the
/// offset basis 14695981039346656037. Not cryptographic: a stable digest that tells two texts or files
/// apart (a run's identity, a shortened file name) and stable numbers for names.

#include <cstdint>
#include <string_view>

namespace gpilqg {

inline constexpr std::uint64_t kFnvOffsetBasis = 14695981039346656037ull;

/// The hash of `bytes` continued from `hash` (the offset basis for a fresh hash; a previous result to
/// hash a file chunk by chunk).
constexpr std::uint64_t fnv1a_64(std::string_view bytes, std::uint64_t hash = kFnvOffsetBasis) {
  for (const char c : bytes) hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  return hash;
}

static_assert(fnv1a_64("") == kFnvOffsetBasis);
static_assert(fnv1a_64("a") == 0xaf63dc4c8601ec8cull);  // the published test vector for "a"

}  // namespace gpilqg
