#pragma once
// The gene regulatory network encoded by a genome (paper §2.1, eq. 1).
//
// Sources of regulation are the 4 special inputs and, per regulatory unit, its internal product and
// its diffusible product (a unit's genes of each kind are expressed at the unit's level). Targets
// are the units (through their promoters) and the 6 outputs. An edge's weight is the sum over all
// product/acceptor element pairs of affinity × sign × sign.
#include <array>
#include <span>
#include <string>
#include <vector>

#include "animat/genome.hpp"

namespace animat {

struct GrnParams {
  double dt = 0.05;  ///< Δt of eq. 1 [paper: 0.05]
};

template <class V>
void visit_fields(GrnParams& p, V&& v) {
  v(FieldInfo{"dt", "time step of eq. 1, dL = (tanh(A/2) - L) dt [paper: 0.05]",
              Bounds{0.0, 1.0, true, false}},
    p.dt);
}

/// Levels of one cell's network: units first, then the outputs (Grn::output_count()). All in [0,
/// 1).
struct GrnState {
  std::vector<double> levels;
  std::vector<double> activation;  ///< scratch for step(); kept here so stepping never allocates
  friend bool operator==(const GrnState&, const GrnState&) = default;
};

/// What a cell senses: maternal morphogen levels and, per morphogen-emitting unit, the sensed
/// concentration of its diffusible product. Empty `morphogens` means "use the cell's own level".
struct GrnInputs {
  std::array<double, 3> maternal{};
  std::span<const double> morphogens{};
  /// Extension inputs strain, pressure, chemical (InputChannel 4-6): 0 during development and
  /// open-loop swims; set by the GRN controller while swimming (docs/control.md).
  std::array<double, kInputCount - kPaperInputCount> sensors{};
};

class Grn {
 public:
  enum class SourceKind { input, internal_product, diffusible_product };
  struct Edge {
    int source;  ///< see source_kind()/source_unit()
    int target;  ///< [0, units) unit, [units, units + output_count()) output
    double weight;
  };

  Grn() = default;
  Grn(const Genome& genome, const GenomeParams& params);

  [[nodiscard]] int unit_count() const { return units_; }
  [[nodiscard]] int node_count() const { return units_ + outputs_; }
  /// Output nodes: the paper's 6, or all kOutputCount when the genome has an extension output
  /// element (so that paper genomes keep their level vectors, units + 6, bit for bit).
  [[nodiscard]] int output_count() const { return outputs_; }
  /// Units with at least one morphogen gene, in unit order; GrnInputs::morphogens follows this
  /// order.
  [[nodiscard]] const std::vector<int>& morphogen_units() const { return morphogen_units_; }
  [[nodiscard]] const std::vector<Edge>& edges() const { return edges_; }
  [[nodiscard]] const GenomeLayout& layout() const { return layout_; }
  [[nodiscard]] int source_count() const { return kInputCount + 2 * units_; }
  [[nodiscard]] SourceKind source_kind(int source) const;
  /// unit of a product source, channel of an input
  [[nodiscard]] int source_unit(int source) const;
  [[nodiscard]] int output_node(OutputChannel c) const { return units_ + static_cast<int>(c); }

  [[nodiscard]] GrnState initial_state() const;
  /// One step of eq. 1 for every unit and output, synchronously. A is clamped at 0 from below, so
  /// each level relaxes towards tanh(max(A,0)/2) ∈ [0, 1) and stays in [0, 1). Allocation-free.
  void step(GrnState& state, const GrnInputs& inputs, const GrnParams& params) const;
  /// The level of output `c`; 0 for an extension output this network has no node for.
  [[nodiscard]] double output(const GrnState& state, OutputChannel c) const {
    return static_cast<int>(c) < outputs_ ? state.levels[static_cast<std::size_t>(output_node(c))]
                                          : 0.0;
  }

  /// Is there a directed path from at least one input to this output?
  [[nodiscard]] bool reaches(OutputChannel c) const;
  /// Viability criterion 1 (paper §5): paths from the inputs to divide and to the three oscillator
  /// outputs.
  [[nodiscard]] bool has_required_paths() const;
  /// The bytes of everything development and a swim read from this network: the unit and output
  /// counts, the morphogen units and every edge with its weight's bits (not to_dot()'s inputs
  /// present, nor which units have an internal gene). Two genomes with equal keys develop the same
  /// embryo bit for bit when development reads nothing else of the genome
  /// (development.jitter_stream = "fixed"): a mutation of an element that takes part in no
  /// interaction leaves the key as it was.
  [[nodiscard]] std::string network_key() const;
  /// Graphviz DOT of the network (inputs, units, outputs; red edges inhibit).
  [[nodiscard]] std::string to_dot() const;

 private:
  int units_ = 0;
  int outputs_ = kPaperOutputCount;
  std::array<bool, kInputCount> has_input_{};  ///< the genome has an element of this input channel
  GenomeLayout layout_;
  std::vector<int> morphogen_units_;
  std::vector<int> morphogen_index_;  ///< unit -> index in morphogen_units_, or -1
  std::vector<bool> has_internal_;    ///< unit has an internal gene
  std::vector<Edge> edges_;           ///< sorted by target, then source
  std::vector<int> target_begin_;     ///< CSR offsets into edges_, size node_count()+1
  std::array<bool, kOutputCount> reachable_{};
};

}  // namespace animat
