#include "animat/genome.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "animat/errors.hpp"
#include "json_util.hpp"

namespace animat {

double affinity(double d, const GenomeParams& p) {
  if (!(d < p.affinity_cutoff)) return 0.0;
  // 10·(e^{-βd} − e^{-βc}) / (1 − e^{-βc}): 10 at d = 0, monotone, exactly 0 at the cut-off c.
  const double tail = std::exp(-p.affinity_decay * p.affinity_cutoff);
  return 10.0 * ((std::exp(-p.affinity_decay * d) - tail) / (1.0 - tail));
}

double distance(const Element& a, const Element& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.coords.size(); ++i) {
    const double d = a.coords[i] - b.coords[i];
    s += d * d;
  }
  return std::sqrt(s);
}

GenomeLayout parse_units(const Genome& genome) {
  GenomeLayout layout;
  const auto& els = genome.elements;
  std::size_t i = 0;
  while (i < els.size()) {
    const Element& e = els[i];
    if (e.type == ElementType::input) {
      layout.inputs.push_back(static_cast<int>(i));
      ++i;
      continue;
    }
    if (e.type == ElementType::output) {
      layout.outputs.push_back(static_cast<int>(i));
      ++i;
      continue;
    }
    if (e.is_gene()) {
      ++i;
      continue;
    }  // gene without promoters: non-coding
    RegulatoryUnit unit;
    while (i < els.size() && els[i].type == ElementType::promoter)
      unit.promoters.push_back(static_cast<int>(i++));
    while (i < els.size() && els[i].is_gene()) unit.genes.push_back(static_cast<int>(i++));
    if (!unit.genes.empty()) layout.units.push_back(std::move(unit));  // else: stray promoters
  }
  return layout;
}

std::uint64_t genome_hash(const Genome& g) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  auto feed = [&h](std::uint64_t x) {
    for (int b = 0; b < 8; ++b) {
      h ^= (x >> (8 * b)) & 0xffU;
      h *= 0x100000001b3ULL;
    }
  };
  feed(static_cast<std::uint64_t>(g.dimensions));
  feed(g.elements.size());
  for (const Element& e : g.elements) {
    feed(static_cast<std::uint64_t>(e.type));
    feed(static_cast<std::uint64_t>(static_cast<std::int64_t>(e.sign)));
    feed(static_cast<std::uint64_t>(e.channel));
    // -0.0 == 0.0
    for (double x : e.coords) feed(std::bit_cast<std::uint64_t>(x == 0.0 ? 0.0 : x));
  }
  return h;
}

std::string_view element_type_name(ElementType t) {
  return kElementTypeNames.at(static_cast<std::size_t>(t));
}

std::string_view channel_name(const Element& e) {
  if (e.type == ElementType::input) return kInputNames.at(static_cast<std::size_t>(e.channel));
  if (e.type == ElementType::output) return kOutputNames.at(static_cast<std::size_t>(e.channel));
  return "";
}

void validate(const Genome& g, const GenomeParams& params, std::string_view source) {
  if (g.dimensions < 1 || g.dimensions > 16)
    throw GenomeError(
        fmt::format("{}: dimensions = {} is out of range [1, 16]", source, g.dimensions));
  if (g.elements.size() > static_cast<std::size_t>(params.max_elements))
    throw GenomeError(fmt::format("{}: {} elements exceed genome.max_elements = {}", source,
                                  g.elements.size(), params.max_elements));
  for (std::size_t i = 0; i < g.elements.size(); ++i) {
    const Element& e = g.elements[i];
    const int t = static_cast<int>(e.type);
    if (t < 0 || t >= kElementTypeCount)
      throw GenomeError(fmt::format("{}: element {}: unknown type {}", source, i, t));
    if (e.sign != 1 && e.sign != -1)
      throw GenomeError(
          fmt::format("{}: element {}: sign = {} (expected +1 or -1)", source, i, e.sign));
    const int channels = e.type == ElementType::input    ? kInputCount
                         : e.type == ElementType::output ? kOutputCount
                                                         : 1;
    if (e.channel < 0 || e.channel >= channels)
      throw GenomeError(fmt::format("{}: element {} ({}): channel {} out of range [0, {})", source,
                                    i, element_type_name(e.type), e.channel, channels));
    if (e.coords.size() != static_cast<std::size_t>(g.dimensions))
      throw GenomeError(fmt::format("{}: element {}: {} coordinates, expected {}", source, i,
                                    e.coords.size(), g.dimensions));
    for (std::size_t k = 0; k < e.coords.size(); ++k)
      if (!std::isfinite(e.coords[k]))
        throw GenomeError(fmt::format("{}: element {}: coordinate {} is {} (must be finite)",
                                      source, i, k, e.coords[k]));
  }
}

namespace {

std::vector<double> random_point(const GenomeParams& p, Rng& rng) {
  std::vector<double> x(static_cast<std::size_t>(p.dimensions));
  for (double& c : x) c = rng.uniform(0.0, p.coord_range);
  return x;
}

Element random_element(ElementType type, int channel, const GenomeParams& p, Rng& rng) {
  Element e;
  e.type = type;
  e.sign = rng.bernoulli(0.5) ? 1 : -1;
  e.channel = channel;
  e.coords = random_point(p, rng);
  return e;
}

}  // namespace

namespace {

/// Parses a comma-separated list of extension channel names (`names[first..]`) into ascending
/// channel numbers appended to the paper's channels 0..first-1.
template <class Names>
std::vector<int> enabled_channels(const std::string& list, const Names& names, int first,
                                  std::string_view key) {
  std::vector<bool> on(names.size(), false);
  const bool blank = list.find_first_not_of(' ') == std::string::npos;  // "" or spaces: none
  std::size_t begin = 0;
  while (!blank && begin <= list.size()) {
    std::size_t end = list.find(',', begin);
    if (end == std::string::npos) end = list.size();
    std::string_view word(list.data() + begin, end - begin);
    while (!word.empty() && word.front() == ' ') word.remove_prefix(1);
    while (!word.empty() && word.back() == ' ') word.remove_suffix(1);
    {
      int c = -1;
      for (int i = first; i < static_cast<int>(names.size()); ++i)
        if (names[static_cast<std::size_t>(i)] == word) c = i;
      if (c < 0)
        throw ConfigError(fmt::format(
            "genome.{} = \"{}\": unknown channel \"{}\" (expected a comma-separated list of {})",
            key, list, word,
            fmt::join(std::vector<std::string_view>(names.begin() + first, names.end()), ", ")));
      if (on[static_cast<std::size_t>(c)])
        throw ConfigError(
            fmt::format("genome.{} = \"{}\": channel \"{}\" is listed twice", key, list, word));
      on[static_cast<std::size_t>(c)] = true;
    }
    begin = end + 1;
  }
  std::vector<int> out;
  for (int c = 0; c < first; ++c) out.push_back(c);
  for (int c = first; c < static_cast<int>(names.size()); ++c)
    if (on[static_cast<std::size_t>(c)]) out.push_back(c);
  return out;
}

}  // namespace

std::vector<int> enabled_input_channels(const GenomeParams& p) {
  return enabled_channels(p.extra_inputs, kInputNames, kPaperInputCount, "extra_inputs");
}

std::vector<int> enabled_output_channels(const GenomeParams& p) {
  return enabled_channels(p.extra_outputs, kOutputNames, kPaperOutputCount, "extra_outputs");
}

Genome random_genome(const GenomeParams& p, Rng& rng) {
  // Units first, then every special element is inserted at a random unit boundary.
  std::vector<std::vector<Element>> blocks;
  for (int u = 0; u < p.initial_units; ++u) {
    const ElementType gene = rng.bernoulli(p.morphogen_gene_probability)
                                 ? ElementType::morphogen_gene
                                 : ElementType::internal_gene;
    blocks.push_back(
        {random_element(ElementType::promoter, 0, p, rng), random_element(gene, 0, p, rng)});
  }
  auto insert_special = [&](ElementType type, int channel) {
    const auto at = static_cast<std::ptrdiff_t>(rng.below(blocks.size() + 1));
    blocks.insert(blocks.begin() + at, std::vector<Element>{random_element(type, channel, p, rng)});
  };
  // Paper channels first, extensions after: with none enabled, the draws are the paper's.
  for (int c : enabled_input_channels(p)) insert_special(ElementType::input, c);
  for (int c : enabled_output_channels(p)) insert_special(ElementType::output, c);
  Genome g;
  g.dimensions = p.dimensions;
  for (auto& b : blocks)
    for (auto& e : b) g.elements.push_back(std::move(e));
  return g;
}

int mutate_types(Genome& g, const MutationParams& m, Rng& rng) {
  return mutate_types(g, m, GenomeParams{}, rng);
}

int mutate_types(Genome& g, const MutationParams& m, const GenomeParams& p, Rng& rng) {
  const std::vector<int> inputs = enabled_input_channels(p);
  const std::vector<int> outputs = enabled_output_channels(p);
  int changes = 0;
  for (Element& e : g.elements) {
    if (!rng.bernoulli(m.type_rate)) continue;
    // Any other type, uniformly; a new special element gets a random channel.
    const int old_type = static_cast<int>(e.type);
    const int new_type =
        (old_type + 1 + static_cast<int>(rng.below(kElementTypeCount - 1))) % kElementTypeCount;
    e.type = static_cast<ElementType>(new_type);
    e.channel = e.type == ElementType::input    ? inputs[rng.below(inputs.size())]
                : e.type == ElementType::output ? outputs[rng.below(outputs.size())]
                                                : 0;
    ++changes;
  }
  return changes;
}

int mutate_signs(Genome& g, const MutationParams& m, Rng& rng) {
  int changes = 0;
  for (Element& e : g.elements)
    if (rng.bernoulli(m.sign_rate)) {
      e.sign = -e.sign;
      ++changes;
    }
  return changes;
}

int mutate_coordinates(Genome& g, const MutationParams& m, Rng& rng) {
  int changes = 0;
  std::vector<double> dir(static_cast<std::size_t>(g.dimensions));
  for (Element& e : g.elements) {
    if (!rng.bernoulli(m.move_rate)) continue;
    // A uniformly random direction (normalised Gaussian vector), a normally distributed distance.
    double norm = 0.0;
    while (norm == 0.0) {
      norm = 0.0;
      for (double& d : dir) {
        d = rng.normal();
        norm += d * d;
      }
      norm = std::sqrt(norm);
    }
    const double step = rng.normal(0.0, m.move_sigma);
    for (std::size_t k = 0; k < dir.size(); ++k) e.coords[k] += step * dir[k] / norm;
    ++changes;
  }
  return changes;
}

void duplicate_series(Genome& g, std::size_t start, std::size_t length) {
  if (start >= g.elements.size() || length == 0) return;
  length = std::min(length, g.elements.size() - start);
  const auto first = g.elements.begin() + static_cast<std::ptrdiff_t>(start);
  std::vector<Element> copy(first, first + static_cast<std::ptrdiff_t>(length));
  g.elements.insert(first + static_cast<std::ptrdiff_t>(length), copy.begin(), copy.end());
}

void delete_series(Genome& g, std::size_t start, std::size_t length) {
  if (start >= g.elements.size() || length == 0) return;
  length = std::min(length, g.elements.size() - start);
  const auto first = g.elements.begin() + static_cast<std::ptrdiff_t>(start);
  g.elements.erase(first, first + static_cast<std::ptrdiff_t>(length));
}

int mutate(Genome& g, const MutationParams& m, const GenomeParams& p, Rng& rng) {
  int changes =
      mutate_types(g, m, p, rng) + mutate_signs(g, m, rng) + mutate_coordinates(g, m, rng);
  if (!g.elements.empty() && rng.bernoulli(m.duplicate_rate)) {
    const std::size_t start = rng.below(g.elements.size());
    const std::size_t length = 1 + rng.below(static_cast<std::uint64_t>(m.max_series_length));
    const std::size_t real = std::min(length, g.elements.size() - start);
    if (g.elements.size() + real <= static_cast<std::size_t>(p.max_elements)) {
      duplicate_series(g, start, real);
      ++changes;
    }
  }
  if (!g.elements.empty() && rng.bernoulli(m.delete_rate)) {
    const std::size_t start = rng.below(g.elements.size());
    const std::size_t length = 1 + rng.below(static_cast<std::uint64_t>(m.max_series_length));
    delete_series(g, start, length);
    ++changes;
  }
  return changes;
}

Genome crossover(const Genome& a, const Genome& b, int points, Rng& rng) {
  if (a.dimensions != b.dimensions)
    throw GenomeError(fmt::format("crossover: parents have {} and {} dimensions; they must match",
                                  a.dimensions, b.dimensions));
  const std::size_t shortest = std::min(a.size(), b.size());
  std::vector<std::size_t> cuts(static_cast<std::size_t>(std::max(points, 0)));
  for (auto& c : cuts) c = rng.below(shortest + 1);
  std::sort(cuts.begin(), cuts.end());
  Genome child;
  child.dimensions = a.dimensions;
  const Genome* parents[2] = {&a, &b};
  std::size_t from = 0;
  int current = 0;
  for (std::size_t cut : cuts) {
    const auto& src = parents[current]->elements;
    child.elements.insert(child.elements.end(), src.begin() + static_cast<std::ptrdiff_t>(from),
                          src.begin() + static_cast<std::ptrdiff_t>(cut));
    from = cut;
    current ^= 1;
  }
  const auto& tail = parents[current]->elements;
  child.elements.insert(child.elements.end(), tail.begin() + static_cast<std::ptrdiff_t>(from),
                        tail.end());
  return child;
}

// ---------------------------------------------------------------------------------------------------
// JSON
using nlohmann::json;

std::string to_json(const Genome& g, int indent) {
  json j;
  j["format"] = "animat.genome";
  j["version"] = kGenomeFormatVersion;
  j["dimensions"] = g.dimensions;
  json els = json::array();
  for (const Element& e : g.elements) {
    json je;
    je["type"] = element_type_name(e.type);
    je["sign"] = e.sign;
    if (e.is_special()) je["channel"] = channel_name(e);
    je["coords"] = e.coords;
    els.push_back(std::move(je));
  }
  j["elements"] = std::move(els);
  return j.dump(indent);
}

namespace {

template <class Names>
int index_of(const Names& names, std::string_view s) {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == s) return static_cast<int>(i);
  return -1;
}

using detail::describe;
using detail::int_in;

const json& require(const json& obj, const char* key, std::string_view where) {
  auto it = obj.find(key);
  if (it == obj.end()) throw GenomeError(fmt::format("{}: missing key \"{}\"", where, key));
  return *it;
}

}  // namespace

Genome genome_from_json(std::string_view text, const GenomeParams& params,
                        std::string_view source) {
  json j;
  try {
    // Elements are objects at depth 2; nothing beyond max_elements + 1 of them is ever built.
    // Parsing stops once the element count is far past the cap (then the exact count is unknown);
    // up to twice the cap, the count is exact.
    j = detail::parse_bounded(text, 16, 2, 2LL * params.max_elements + 1000);
  } catch (const detail::JsonLimit& e) {
    if (std::string_view(e.what()).starts_with("more than"))
      throw GenomeError(fmt::format(
          "{}: more than {} elements exceed genome.max_elements = {} (parsing stopped there)",
          source, 2LL * params.max_elements + 1000, params.max_elements));
    throw GenomeError(fmt::format("{}: not a genome: {}", source, e.what()));
  } catch (const json::parse_error& e) {
    throw GenomeError(fmt::format("{}: not valid JSON (at byte {}): {}", source, e.byte, e.what()));
  } catch (const json::exception& e) {  // e.g. a number too large for a double (1e999)
    throw GenomeError(fmt::format("{}: not valid genome JSON: {}", source, e.what()));
  }
  if (!j.is_object())
    throw GenomeError(fmt::format("{}: expected a JSON object at the top level", source));
  try {
    const std::string where(source);
    const json& format = require(j, "format", where);
    if (!format.is_string() || format.get<std::string>() != "animat.genome")
      throw GenomeError(fmt::format("{}: \"format\" is {}, expected \"animat.genome\"", source,
                                    describe(format)));
    const json& version = require(j, "version", where);
    if (int_in(version, kGenomeFormatVersion, kGenomeFormatVersion) == std::nullopt)
      throw GenomeError(fmt::format("{}: unsupported \"version\" {} (this build reads version {})",
                                    source, describe(version), kGenomeFormatVersion));
    const json& dims = require(j, "dimensions", where);
    if (int_in(dims, 1, 16) == std::nullopt)
      throw GenomeError(fmt::format("{}: \"dimensions\" is {}, expected an integer in [1, 16]",
                                    source, describe(dims)));
    const json& els = require(j, "elements", where);
    if (!els.is_array())
      throw GenomeError(fmt::format("{}: \"elements\" must be an array", source));
    if (els.size() > static_cast<std::size_t>(params.max_elements))
      throw GenomeError(fmt::format("{}: {} elements exceed genome.max_elements = {}", source,
                                    els.size(), params.max_elements));
    Genome g;
    g.dimensions = dims.get<int>();
    g.elements.reserve(els.size());
    for (std::size_t i = 0; i < els.size(); ++i) {
      const json& je = els[i];
      const std::string at = fmt::format("{}: element {}", source, i);
      if (!je.is_object()) throw GenomeError(at + ": expected an object");
      Element e;
      const json& type = require(je, "type", at);
      const int t = type.is_string() ? index_of(kElementTypeNames, type.get<std::string>()) : -1;
      if (t < 0)
        throw GenomeError(
            fmt::format("{}: unknown type {} (expected one of promoter, internal_gene, "
                        "morphogen_gene, input, output)",
                        at, describe(type)));
      e.type = static_cast<ElementType>(t);
      const json& sign = require(je, "sign", at);
      const auto sign_value = int_in(sign, -1, 1);
      if (sign_value == std::nullopt || *sign_value == 0)
        throw GenomeError(fmt::format("{}: sign is {}, expected 1 or -1", at, describe(sign)));
      e.sign = static_cast<int>(*sign_value);
      if (e.is_special()) {
        const json& ch = require(je, "channel", at);
        const int c = !ch.is_string() ? -1
                      : e.type == ElementType::input
                          ? index_of(kInputNames, ch.get<std::string>())
                          : index_of(kOutputNames, ch.get<std::string>());
        if (c < 0) {
          const std::string names = e.type == ElementType::input
                                        ? fmt::format("{}", fmt::join(kInputNames, ", "))
                                        : fmt::format("{}", fmt::join(kOutputNames, ", "));
          // a number is not accepted even where it is a channel's index: names only
          if (!ch.is_string())
            throw GenomeError(
                fmt::format("{}: channel {} must be a name, one of the {} channels ({})", at,
                            describe(ch), element_type_name(e.type), names));
          throw GenomeError(fmt::format("{}: channel {} is not a valid {} channel ({})", at,
                                        describe(ch), element_type_name(e.type), names));
        }
        e.channel = c;
      } else if (je.contains("channel")) {
        throw GenomeError(fmt::format("{}: {} {} has no channel", at,
                                      element_type_name(e.type).front() == 'i' ? "an" : "a",
                                      element_type_name(e.type)));
      }
      const json& coords = require(je, "coords", at);
      if (!coords.is_array() || coords.size() != static_cast<std::size_t>(g.dimensions))
        throw GenomeError(fmt::format("{}: coords must be an array of {} numbers, got {}", at,
                                      g.dimensions, describe(coords)));
      for (std::size_t k = 0; k < coords.size(); ++k) {
        if (!coords[k].is_number())
          throw GenomeError(fmt::format("{}: coordinate {} is {}, expected a number", at, k,
                                        describe(coords[k])));
        const double x = coords[k].get<double>();
        if (!std::isfinite(x))
          throw GenomeError(fmt::format("{}: coordinate {} is {} (must be finite)", at, k, x));
        e.coords.push_back(x);
      }
      g.elements.push_back(std::move(e));
    }
    validate(g, params, source);
    return g;
  } catch (const json::exception& e) {
    throw GenomeError(fmt::format("{}: malformed genome: {}", source, e.what()));
  }
}

Genome load_genome(const std::filesystem::path& path, const GenomeParams& params) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw IoError(fmt::format("{}: cannot read genome file: Is a directory", path.string()));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("{}: cannot open genome file", path.string()));
  std::ostringstream ss;
  ss << in.rdbuf();
  return genome_from_json(ss.str(), params, path.string());
}

void save_genome(const Genome& genome, const std::filesystem::path& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw IoError(fmt::format("{}: cannot open for writing", path.string()));
  out << to_json(genome, 1) << '\n';
  if (!out.flush()) throw IoError(fmt::format("{}: write failed", path.string()));
}

}  // namespace animat
