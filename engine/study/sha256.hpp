#pragma once
// SHA-256 (FIPS 180-4), for the study file's fingerprint stored beside the results.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace ks {

class Sha256 {
 public:
  Sha256();
  void update(std::string_view bytes);
  /// Finish and return the 32-byte digest; the object must not be updated afterwards.
  std::array<std::uint8_t, 32> digest();

 private:
  void block(const std::uint8_t* p);
  std::array<std::uint32_t, 8> h_;
  std::array<std::uint8_t, 64> buf_{};
  std::size_t buf_len_ = 0;
  std::uint64_t total_ = 0;  // bytes
};

/// Lower-case hex SHA-256 of `bytes` (64 characters).
std::string sha256_hex(std::string_view bytes);

}  // namespace ks
