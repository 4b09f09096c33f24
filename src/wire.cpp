#include "animat/wire.hpp"

#include <fmt/format.h>

namespace animat::wire {

namespace {
constexpr std::uint32_t kMaxElements = 100000000;  // far above genome.max_elements' bound (1e6)
constexpr std::uint32_t kMaxString = 1u << 30;
}  // namespace

void Writer::string(std::string_view s) {
  put(static_cast<std::uint32_t>(s.size()));
  const std::size_t at = bytes_.size();
  bytes_.resize(at + s.size());
  if (!s.empty()) std::memcpy(bytes_.data() + at, s.data(), s.size());
}

void Writer::genome(const Genome& g) {
  put(static_cast<std::int32_t>(g.dimensions));
  put(static_cast<std::uint32_t>(g.elements.size()));
  for (const Element& e : g.elements) {
    const auto& [type, sign, channel, coords] =
        e;  // a new Element field must be added here (and in Reader)
    put(static_cast<std::uint8_t>(type));
    put(static_cast<std::int8_t>(sign));
    put(static_cast<std::int32_t>(channel));
    put(static_cast<std::uint32_t>(coords.size()));
    for (double c : coords) put(c);
  }
}

// A Fitness field by field, in its descriptor's order (evolution.hpp): f64, bools as u8, int as
// i32, long as i64.
void Writer::fitness(const Fitness& f) {
  visit_fields(f, [this](const char*, const char*, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    if constexpr (std::is_same_v<T, bool>)
      put(static_cast<std::uint8_t>(value));
    else if constexpr (std::is_same_v<T, int>)
      put(static_cast<std::int32_t>(value));
    else if constexpr (std::is_same_v<T, long>)
      put(static_cast<std::int64_t>(value));
    else
      put(value);
  });
}

void Reader::need(std::size_t n) const {
  if (n > size_ - pos_)
    throw Error(fmt::format("MPI message truncated: {} more bytes needed at byte {} of {}", n, pos_,
                            size_));
}

std::string Reader::string() {
  const auto n = get<std::uint32_t>();
  if (n > kMaxString) throw Error(fmt::format("MPI message: string of {} bytes", n));
  need(n);
  std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
  pos_ += n;
  return s;
}

Genome Reader::genome() {
  Genome g;
  g.dimensions = get<std::int32_t>();
  const auto n = get<std::uint32_t>();
  if (n > kMaxElements) throw Error(fmt::format("MPI message: genome of {} elements", n));
  g.elements.resize(n);
  for (Element& e : g.elements) {
    const auto type = get<std::uint8_t>();
    if (type >= kElementTypeCount) throw Error(fmt::format("MPI message: element type {}", type));
    e.type = static_cast<ElementType>(type);
    e.sign = get<std::int8_t>();
    e.channel = get<std::int32_t>();
    const auto dims = get<std::uint32_t>();
    need(static_cast<std::size_t>(dims) * sizeof(double));
    e.coords.resize(dims);
    for (double& c : e.coords) c = get<double>();
  }
  return g;
}

Fitness Reader::fitness() {
  Fitness f;
  visit_fields(f, [this](const char*, const char*, auto& value) {
    using T = std::decay_t<decltype(value)>;
    if constexpr (std::is_same_v<T, bool>)
      value = get<std::uint8_t>() != 0;
    else if constexpr (std::is_same_v<T, int>)
      value = get<std::int32_t>();
    else if constexpr (std::is_same_v<T, long>)
      value = static_cast<long>(get<std::int64_t>());
    else
      value = get<T>();
  });
  return f;
}

std::size_t genome_bytes(const Genome& g) {
  Writer w;
  w.genome(g);
  return w.bytes().size();
}

}  // namespace animat::wire
