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
    // a new Element field must be added here (and in Reader)
    const auto& [type, sign, channel, coords] = e;
    put(static_cast<std::uint8_t>(type));
    put(static_cast<std::int8_t>(sign));
    put(static_cast<std::int32_t>(channel));
    put(static_cast<std::uint32_t>(coords.size()));
    for (double c : coords) put(c);
  }
}

void Writer::fitness(const Fitness& f) {
  // a new Fitness field must be added here (and in Reader)
  const auto& [value, viable, stable, cell_count, valid, drag_limited] = f;
  put(value);
  put(static_cast<std::uint8_t>(viable));
  put(static_cast<std::uint8_t>(stable));
  put(static_cast<std::int32_t>(cell_count));
  put(static_cast<std::uint8_t>(valid));
  put(static_cast<std::int64_t>(drag_limited));
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
  f.fitness = get<double>();
  f.viable = get<std::uint8_t>() != 0;
  f.stable = get<std::uint8_t>() != 0;
  f.cell_count = get<std::int32_t>();
  f.valid = get<std::uint8_t>() != 0;
  f.drag_limited = static_cast<long>(get<std::int64_t>());
  return f;
}

std::size_t genome_bytes(const Genome& g) {
  Writer w;
  w.genome(g);
  return w.bytes().size();
}

}  // namespace animat::wire
