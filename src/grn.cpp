#include "animat/grn.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>

namespace animat {

namespace {
constexpr double kBelowOne = 1.0 - 0x1.0p-53;  // the largest double below 1
}  // namespace

Grn::Grn(const Genome& genome, const GenomeParams& params) : layout_(parse_units(genome)) {
  units_ = static_cast<int>(layout_.units.size());
  for (int oi : layout_.outputs)
    if (genome.elements[static_cast<std::size_t>(oi)].channel >= kPaperOutputCount)
      outputs_ = kOutputCount;
  for (int ei : layout_.inputs)
    has_input_[static_cast<std::size_t>(genome.elements[static_cast<std::size_t>(ei)].channel)] =
        true;
  morphogen_index_.assign(static_cast<std::size_t>(units_), -1);
  has_internal_.assign(static_cast<std::size_t>(units_), false);
  for (int u = 0; u < units_; ++u) {
    bool diffusible = false;
    for (int gi : layout_.units[static_cast<std::size_t>(u)].genes) {
      if (genome.elements[static_cast<std::size_t>(gi)].type == ElementType::morphogen_gene)
        diffusible = true;
      else
        has_internal_[static_cast<std::size_t>(u)] = true;
    }
    if (diffusible) {
      morphogen_index_[static_cast<std::size_t>(u)] = static_cast<int>(morphogen_units_.size());
      morphogen_units_.push_back(u);
    }
  }

  // (source element, source node) and (acceptor element, target node) lists.
  std::vector<std::pair<int, int>> products, acceptors;
  // Source numbering: the paper's inputs 0-3, internal products 4..4+U, diffusible products
  // 4+U..4+2U, then the extension inputs (strain, pressure, chemical) 4+2U..4+2U+3, so that a paper
  // genome's sources (and the edge order) are what they always were.
  for (int ei : layout_.inputs) {
    const int c = genome.elements[static_cast<std::size_t>(ei)].channel;
    products.emplace_back(ei, c < kPaperInputCount ? c : c + 2 * units_);
  }
  for (int u = 0; u < units_; ++u) {
    for (int gi : layout_.units[static_cast<std::size_t>(u)].genes) {
      const bool morph =
          genome.elements[static_cast<std::size_t>(gi)].type == ElementType::morphogen_gene;
      products.emplace_back(gi, kPaperInputCount + (morph ? units_ : 0) + u);
    }
    for (int pi : layout_.units[static_cast<std::size_t>(u)].promoters)
      acceptors.emplace_back(pi, u);
  }
  for (int oi : layout_.outputs)
    acceptors.emplace_back(oi, units_ + genome.elements[static_cast<std::size_t>(oi)].channel);

  // (target, source) -> weight; ordered for determinism
  std::map<std::pair<int, int>, double> merged;
  for (const auto& [ae, target] : acceptors) {
    const Element& a = genome.elements[static_cast<std::size_t>(ae)];
    for (const auto& [pe, source] : products) {
      const Element& p = genome.elements[static_cast<std::size_t>(pe)];
      const double w = affinity(distance(a, p), params);
      if (w > 0.0) merged[{target, source}] += w * a.sign * p.sign;
    }
  }
  edges_.reserve(merged.size());
  for (const auto& [key, w] : merged) edges_.push_back({key.second, key.first, w});
  target_begin_.assign(static_cast<std::size_t>(node_count()) + 1, 0);
  for (const Edge& e : edges_) ++target_begin_[static_cast<std::size_t>(e.target) + 1];
  for (std::size_t i = 1; i < target_begin_.size(); ++i) target_begin_[i] += target_begin_[i - 1];

  // Reachability from the inputs over the source->target relation; a unit node feeds the product
  // sources of that unit.
  std::vector<bool> node_reached(static_cast<std::size_t>(node_count()), false);
  std::vector<bool> source_reached(static_cast<std::size_t>(source_count()), false);
  for (int c = 0; c < kInputCount; ++c)
    source_reached[static_cast<std::size_t>(c < kPaperInputCount ? c : c + 2 * units_)] = true;
  for (bool changed = true; changed;) {
    changed = false;
    for (const Edge& e : edges_) {
      if (!source_reached[static_cast<std::size_t>(e.source)] ||
          node_reached[static_cast<std::size_t>(e.target)])
        continue;
      node_reached[static_cast<std::size_t>(e.target)] = true;
      changed = true;
      if (e.target < units_) {
        source_reached[static_cast<std::size_t>(kPaperInputCount + e.target)] = true;
        source_reached[static_cast<std::size_t>(kPaperInputCount + units_ + e.target)] = true;
      }
    }
  }
  for (int c = 0; c < outputs_; ++c)
    reachable_[static_cast<std::size_t>(c)] = node_reached[static_cast<std::size_t>(units_ + c)];
}

Grn::SourceKind Grn::source_kind(int s) const {
  if (s < kPaperInputCount || s >= kPaperInputCount + 2 * units_) return SourceKind::input;
  return s < kPaperInputCount + units_ ? SourceKind::internal_product
                                       : SourceKind::diffusible_product;
}

int Grn::source_unit(int s) const {
  if (s < kPaperInputCount) return s;
  if (s >= kPaperInputCount + 2 * units_) return s - 2 * units_;  // an extension input's channel
  return (s - kPaperInputCount) % std::max(units_, 1);
}

std::string Grn::network_key() const {
  std::string key;
  auto put = [&key](auto value) {
    const auto bytes = std::bit_cast<std::array<char, sizeof value>>(value);
    key.append(bytes.data(), bytes.size());
  };
  put(units_);
  put(outputs_);
  put(morphogen_units_.size());
  for (const int u : morphogen_units_) put(u);
  // the rest is the edges (their count follows from the key's length): weights by their bits, so
  // that equal keys mean the same sums in step()
  for (const Edge& e : edges_) {
    put(e.source);
    put(e.target);
    put(std::bit_cast<std::uint64_t>(e.weight));
  }
  return key;
}

GrnState Grn::initial_state() const {
  GrnState s;
  s.levels.assign(static_cast<std::size_t>(node_count()), 0.0);
  s.activation.assign(static_cast<std::size_t>(node_count()), 0.0);
  return s;
}

void Grn::step(GrnState& state, const GrnInputs& in, const GrnParams& params) const {
  const double* level = state.levels.data();
  double* act = state.activation.data();
  auto concentration = [&](int s) -> double {
    if (s < kPaperInputCount) return s == 0 ? 1.0 : in.maternal[static_cast<std::size_t>(s - 1)];
    if (s < kPaperInputCount + units_) return level[s - kPaperInputCount];
    if (s >= kPaperInputCount + 2 * units_)
      return in.sensors[static_cast<std::size_t>(s - kPaperInputCount - 2 * units_)];
    const int u = s - kPaperInputCount - units_;
    const int m = morphogen_index_[static_cast<std::size_t>(u)];
    return in.morphogens.empty() ? level[u] : in.morphogens[static_cast<std::size_t>(m)];
  };
  const int nodes = node_count();
  for (int t = 0; t < nodes; ++t) {
    double a = 0.0;
    for (int k = target_begin_[static_cast<std::size_t>(t)];
         k < target_begin_[static_cast<std::size_t>(t) + 1]; ++k)
      a += edges_[static_cast<std::size_t>(k)].weight *
           concentration(edges_[static_cast<std::size_t>(k)].source);
    act[t] = a;
  }
  for (int t = 0; t < nodes; ++t) {
    // tanh rounds to exactly 1 for A > ~38; the paper's range is [0, 1), so the target stays below
    // 1 and the convex update keeps the level below it for every dt in (0, 1]. A silent node (A <=
    // 0) skips the tanh: its target is 0 either way (the level is the same bit for bit, +0 and -0
    // alike); a NaN still goes through tanh as before.
    const double x = act[t];
    const double target = x <= 0.0 ? 0.0 : std::min(std::tanh(std::max(x, 0.0) * 0.5), kBelowOne);
    state.levels[static_cast<std::size_t>(t)] +=
        (target - state.levels[static_cast<std::size_t>(t)]) * params.dt;
  }
}

bool Grn::reaches(OutputChannel c) const { return reachable_[static_cast<std::size_t>(c)]; }

bool Grn::has_required_paths() const {
  return reaches(OutputChannel::divide) && reaches(OutputChannel::amplitude) &&
         reaches(OutputChannel::frequency) && reaches(OutputChannel::phase);
}

std::string Grn::to_dot() const {
  std::string out = "digraph grn {\n  rankdir=LR;\n";
  for (int c = 0; c < kInputCount; ++c)
    // extension inputs only when used
    if (c < kPaperInputCount || has_input_[static_cast<std::size_t>(c)])
      out += fmt::format("  in{} [label=\"{}\", shape=box, style=filled, fillcolor=lightblue];\n",
                         c, kInputNames[static_cast<std::size_t>(c)]);
  for (int u = 0; u < units_; ++u)
    out += fmt::format("  u{} [label=\"unit {}{}\"];\n", u, u,
                       morphogen_index_[static_cast<std::size_t>(u)] >= 0 ? " (morphogen)" : "");
  for (int c = 0; c < outputs_; ++c)
    out += fmt::format("  out{} [label=\"{}\", shape=box, style=filled, fillcolor=lightyellow];\n",
                       c, kOutputNames[static_cast<std::size_t>(c)]);
  for (const Edge& e : edges_) {
    const std::string src = source_kind(e.source) == SourceKind::input
                                ? fmt::format("in{}", source_unit(e.source))
                                : fmt::format("u{}", source_unit(e.source));
    const std::string dst =
        e.target < units_ ? fmt::format("u{}", e.target) : fmt::format("out{}", e.target - units_);
    out += fmt::format(
        "  {} -> {} [label=\"{:.3g}\", color={}{}];\n", src, dst, e.weight,
        e.weight < 0 ? "red" : "black",
        source_kind(e.source) == SourceKind::diffusible_product ? ", style=dashed" : "");
  }
  return out + "}\n";
}

}  // namespace animat
