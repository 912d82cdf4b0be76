#pragma once
// Little binary streams for checkpoints. Values are written in the machine's native layout
// (checkpoints are for restarting on the same kind of machine; the header records the layout
// and a mismatch is reported instead of misread).
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace monolith {

class BinaryWriter {
 public:
  template <class T>
  void pod(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void raw(const void* data, std::size_t size) {
    const auto* p = static_cast<const std::uint8_t*>(data);
    bytes_.insert(bytes_.end(), p, p + size);
  }
  void string(const std::string& s) {
    pod<std::uint64_t>(s.size());
    raw(s.data(), s.size());
  }
  template <class T>
  void vector(const std::vector<T>& v) {
    pod<std::uint64_t>(v.size());
    if (!v.empty()) raw(v.data(), v.size() * sizeof(T));
  }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

class BinaryReader {
 public:
  BinaryReader(const std::uint8_t* data, std::size_t size, std::string what)
      : data_(data), size_(size), what_(std::move(what)) {}
  template <class T>
  T pod() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, take(sizeof(T)), sizeof(T));
    return value;
  }
  void raw(void* out, std::size_t size) { std::memcpy(out, take(size), size); }
  std::string string() {
    const auto n = pod<std::uint64_t>();
    const auto* p = take(n);
    return std::string(reinterpret_cast<const char*>(p), n);
  }
  template <class T>
  std::vector<T> vector() {
    const auto n = pod<std::uint64_t>();
    if (n > (size_ - pos_) / (sizeof(T) ? sizeof(T) : 1)) fail("vector length exceeds the data");
    std::vector<T> v(n);
    if (n) raw(v.data(), n * sizeof(T));
    return v;
  }
  bool atEnd() const { return pos_ == size_; }
  std::size_t remaining() const { return size_ - pos_; }
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error(what_ + ": corrupt or truncated data at byte " + std::to_string(pos_) + " (" + why + ")");
  }

 private:
  const std::uint8_t* take(std::size_t n) {
    if (n > size_ - pos_) fail("wanted " + std::to_string(n) + " bytes, " + std::to_string(size_ - pos_) + " left");
    const auto* p = data_ + pos_;
    pos_ += n;
    return p;
  }
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string what_;
};

// FNV-1a over bytes: the state hash that determinism tests and summary.json compare.
inline std::uint64_t fnv1a(const std::uint8_t* data, std::size_t size, std::uint64_t h = 14695981039346656037ull) {
  for (std::size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace monolith
