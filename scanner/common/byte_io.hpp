#pragma once
// Little-endian binary encoding for uwscan's own versioned files (object databases): a writer
// that appends to a string and a reader that names the file and the field when it runs short.

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>

#include "scanner/common/error.hpp"

namespace uwscan {

class ByteWriter {
 public:
  template <typename T>
  void Put(T value) {
    static_assert(std::is_arithmetic_v<T>);
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    bytes_.append(raw, sizeof(T));  // the machines uwscan targets are little-endian
  }
  void PutString(const std::string& s) {
    Put<std::uint32_t>(static_cast<std::uint32_t>(s.size()));
    bytes_ += s;
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  // `what_file` names the file in errors; reads stop at `end`.
  ByteReader(const std::string& bytes, std::size_t begin, std::size_t end, std::string what_file)
      : bytes_(bytes), pos_(begin), end_(end), file_(std::move(what_file)) {}

  template <typename T>
  T Get(const char* field) {
    static_assert(std::is_arithmetic_v<T>);
    Need(sizeof(T), field);
    T value;
    std::memcpy(&value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  // A length-prefixed string of at most max_size bytes.
  std::string GetString(const char* field, std::size_t max_size) {
    const std::uint32_t size = Get<std::uint32_t>(field);
    if (size > max_size) Fail(std::string(field) + " is " + std::to_string(size) + " bytes long");
    Need(size, field);
    std::string s = bytes_.substr(pos_, size);
    pos_ += size;
    return s;
  }
  // A count that the remaining bytes could hold at `bytes_each` bytes per item.
  std::size_t GetCount(const char* field, std::size_t bytes_each) {
    const std::uint64_t count = Get<std::uint64_t>(field);
    if (bytes_each > 0 && count > (end_ - pos_) / bytes_each) {
      Fail(std::string(field) + " says " + std::to_string(count) + " but the file is too short");
    }
    return static_cast<std::size_t>(count);
  }
  bool at_end() const { return pos_ == end_; }
  std::size_t position() const { return pos_; }
  [[noreturn]] void Fail(const std::string& what) const {
    throw Error(file_ + ": corrupt at byte " + std::to_string(pos_) + ": " + what);
  }

 private:
  void Need(std::size_t size, const char* field) const {
    if (end_ - pos_ < size) {
      throw Error(file_ + ": truncated at byte " + std::to_string(pos_) + " while reading " +
                  field);
    }
  }
  const std::string& bytes_;
  std::size_t pos_;
  std::size_t end_;
  std::string file_;
};

}  // namespace uwscan
