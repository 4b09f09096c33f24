#pragma once
// A compact binary encoding of genomes and fitness for the messages between MPI ranks (mpi.hpp).
// Numbers travel as their bytes (doubles bit for bit), so a genome evaluated on another rank is the
// same genome, and its fitness comes back unchanged: layouts cannot change results.
// Both ends run the same build; byte order is the machine's (an MPI job is one architecture).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "animat/errors.hpp"
#include "animat/evolution.hpp"
#include "animat/genome.hpp"

namespace animat::wire {

class Writer {
 public:
  template <class T>
  void put(T value) {
    static_assert(std::is_arithmetic_v<T>);
    const std::size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));  // resize + memcpy: GCC 12 -O3 misreports insert() of raw bytes
    std::memcpy(bytes_.data() + at, &value, sizeof(T));
  }
  void string(std::string_view s);
  void genome(const Genome& g);
  void fitness(const Fitness& f);

  [[nodiscard]] const std::vector<unsigned char>& bytes() const { return bytes_; }
  [[nodiscard]] std::vector<unsigned char> take() { return std::move(bytes_); }

 private:
  std::vector<unsigned char> bytes_;
};

/// Reads what a Writer wrote; a truncated or malformed message throws Error (never reads past the
/// end).
class Reader {
 public:
  Reader(const unsigned char* data, std::size_t size) : data_(data), size_(size) {}
  explicit Reader(const std::vector<unsigned char>& v) : Reader(v.data(), v.size()) {}

  template <class T>
  T get() {
    static_assert(std::is_arithmetic_v<T>);
    need(sizeof(T));
    T value;
    std::memcpy(&value, data_ + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  std::string string();
  Genome genome();
  Fitness fitness();

  [[nodiscard]] bool done() const { return pos_ == size_; }

 private:
  void need(std::size_t n) const;
  const unsigned char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

/// Bytes of a genome on the wire (for the communication model in docs/performance.md).
[[nodiscard]] std::size_t genome_bytes(const Genome& g);

}  // namespace animat::wire
