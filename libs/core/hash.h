// 64-bit FNV-1a content hash (for provenance: identifies input files, not security).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace jvl {

class Fnv1a64 {
 public:
  void Update(const void* data, size_t size);
  uint64_t value() const { return state_; }
  // 16 lowercase hex digits.
  std::string Hex() const;

 private:
  uint64_t state_ = 0xcbf29ce484222325ULL;
};

}  // namespace jvl
