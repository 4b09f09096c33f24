#pragma once
// The linear genome of paper §2.1 (Fig. 1): a list of elements with a type, a sign and a point in
// an N-dimensional affinity space, plus its genetic operators and JSON form.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "animat/params.hpp"
#include "animat/random.hpp"

namespace animat {

enum class ElementType : std::uint8_t {
  promoter = 0,        ///< regulatory region
  internal_gene = 1,   ///< codes for a TF acting only in its own cell
  morphogen_gene = 2,  ///< codes for a diffusible TF (a morphogen)
  input = 3,           ///< special input: acts like a TF (bias, maternal morphogens)
  output = 4,          ///< special output: acts like a one-gene regulatory unit
};
inline constexpr int kElementTypeCount = 5;

/// Special inputs [paper §2.1]: a constant 1 and three maternal morphogens (channels 0-3), then the
/// extension channels beyond the paper (docs/model.md, "Genome channels"): sensors a cell reads
/// while it swims under control.mode = "grn" (docs/control.md). Channel numbers are fixed forever:
/// genome files name channels, and run identity depends on which are enabled.
enum class InputChannel : int {
  bias = 0,
  maternal0 = 1,
  maternal1 = 2,
  maternal2 = 3,
  strain = 4,    ///< mean relative stretch of the cell's springs (swim only)
  pressure = 5,  ///< mean S/S0 of the cell's regions (swim only)
  chemical = 6,  ///< the scene's chemical field at the cell (swim only)
};
/// Every known input channel (the paper's and the extensions).
inline constexpr int kInputCount = 7;
/// The paper's input channels: 0 .. kPaperInputCount-1. Always enabled.
inline constexpr int kPaperInputCount = 4;
/// Special outputs [paper §2.1]: three developmental actions and three oscillator parameters
/// (channels 0-5), then the extension channels.
enum class OutputChannel : int {
  divide = 0,
  rotate = 1,
  grow = 2,
  amplitude = 3,
  frequency = 4,
  phase = 5,
  /// per-cell spring stiffness factor (evolvable stiffness; development.stiffness_min/max)
  stiffness = 6,
  actuation = 7,  ///< the cell's actuation term u_i under control.mode = "grn"
};
/// Every known output channel (the paper's and the extensions).
inline constexpr int kOutputCount = 8;
/// The paper's output channels: 0 .. kPaperOutputCount-1. Always enabled.
inline constexpr int kPaperOutputCount = 6;

inline constexpr std::array<std::string_view, kElementTypeCount> kElementTypeNames = {
    "promoter", "internal_gene", "morphogen_gene", "input", "output"};
inline constexpr std::array<std::string_view, kInputCount> kInputNames = {
    "bias", "maternal0", "maternal1", "maternal2", "strain", "pressure", "chemical"};
inline constexpr std::array<std::string_view, kOutputCount> kOutputNames = {
    "divide", "rotate", "grow", "amplitude", "frequency", "phase", "stiffness", "actuation"};

/// One genetic element. `channel` names the input or output of a special element and is 0
/// otherwise.
struct Element {
  ElementType type = ElementType::promoter;
  int sign = 1;  ///< +1 or -1; an interaction's sign is the product of both signs
  int channel = 0;
  std::vector<double> coords;  ///< point in affinity space, size == Genome::dimensions

  [[nodiscard]] bool is_gene() const {
    return type == ElementType::internal_gene || type == ElementType::morphogen_gene;
  }
  [[nodiscard]] bool is_special() const {
    return type == ElementType::input || type == ElementType::output;
  }
  friend bool operator==(const Element&, const Element&) = default;
};

struct Genome {
  int dimensions = 2;
  std::vector<Element> elements;

  [[nodiscard]] std::size_t size() const { return elements.size(); }
  friend bool operator==(const Genome&, const Genome&) = default;
};

/// Genome-level parameters: affinity space, affinity function and the random initial genome.
struct GenomeParams {
  int dimensions = 2;            ///< N of the affinity space [paper: 2]
  double coord_range = 10.0;     ///< random coordinates are uniform in [0, coord_range)^N
  double affinity_decay = 1.0;   ///< exponential decay rate of the affinity with distance
  double affinity_cutoff = 2.0;  ///< distance at and beyond which the affinity is exactly 0
  int initial_units = 10;        ///< regulatory units of a random genome [paper: 10]
  double morphogen_gene_probability = 0.25;  ///< chance that a random gene codes for a morphogen
  int max_elements = 10000;                  ///< safety cap: longer genomes are rejected as absurd
  /// Extension input channels (beyond the paper's 4) that random genomes and mutations may create:
  /// comma-separated names from strain, pressure, chemical; "" = none (the paper's genome).
  std::string extra_inputs;
  /// Extension output channels that random genomes and mutations may create: comma-separated names
  /// from stiffness, actuation; "" = none.
  std::string extra_outputs;
};

/// Rates of the genetic operators (paper §5). Per-element rates apply to every element
/// independently.
struct MutationParams {
  double type_rate = 0.005;      ///< per element: change the type
  double sign_rate = 0.005;      ///< per element: flip the sign
  double move_rate = 0.05;       ///< per element: move the point in a random direction
  double move_sigma = 0.5;       ///< std. dev. of the distance of a move
  double duplicate_rate = 0.05;  ///< per genome: duplicate a series of elements
  double delete_rate = 0.05;     ///< per genome: delete a series of elements
  int max_series_length = 4;     ///< longest duplicated or deleted series
  int crossover_points = 2;      ///< cut points of multipoint crossover
};

template <class V>
void visit_fields(GenomeParams& p, V&& v) {
  v(FieldInfo{"dimensions", "dimension N of the affinity space [paper: 2]", Bounds::closed(1, 16)},
    p.dimensions);
  v(FieldInfo{"coord_range", "random coordinates are uniform in [0, coord_range)^N [choose]",
              Bounds::positive_upto(kMaxLength)},
    p.coord_range);
  v(FieldInfo{"affinity_decay", "exponential decay rate of the affinity with distance [choose]",
              Bounds::closed(1e-6, 1e6)},
    p.affinity_decay);
  v(FieldInfo{"affinity_cutoff", "distance at which the affinity reaches exactly 0 [choose]",
              Bounds::closed(1e-6, 1e6)},
    p.affinity_cutoff);
  v(FieldInfo{"initial_units", "regulatory units (promoter + gene) in a random genome [paper: 10]",
              Bounds::closed(0, 1000)},
    p.initial_units);
  v(FieldInfo{"morphogen_gene_probability",
              "chance that a random gene codes for a morphogen [choose]", Bounds::unit()},
    p.morphogen_gene_probability);
  v(FieldInfo{"max_elements", "safety cap on genome length; longer genomes are rejected [choose]",
              Bounds::closed(1, 1000000)},
    p.max_elements);
  v(FieldInfo{"extra_inputs",
              "extension input channels random genomes and mutations may create, comma-separated: "
              "strain, pressure, chemical; \"\" = the paper's 4 inputs only (docs/model.md) "
              "[beyond the paper]",
              Bounds::any(),
              {},
              Identity::late},
    p.extra_inputs);
  v(FieldInfo{"extra_outputs",
              "extension output channels random genomes and mutations may create, comma-separated: "
              "stiffness, actuation; \"\" = the paper's 6 outputs only (docs/model.md) [beyond the "
              "paper]",
              Bounds::any(),
              {},
              Identity::late},
    p.extra_outputs);
}

/// The input channels random genomes and mutations draw from: the paper's 0-3, then the enabled
/// extension channels in ascending channel order (whatever order genome.extra_inputs lists them).
/// Throws ConfigError naming genome.extra_inputs and the value for an unknown or repeated name.
[[nodiscard]] std::vector<int> enabled_input_channels(const GenomeParams& params);
/// The same for outputs: 0-5, then the enabled extensions (genome.extra_outputs).
[[nodiscard]] std::vector<int> enabled_output_channels(const GenomeParams& params);

template <class V>
void visit_fields(MutationParams& p, V&& v) {
  v(FieldInfo{"type_rate", "per-element probability of a type change [choose]", Bounds::unit()},
    p.type_rate);
  v(FieldInfo{"sign_rate", "per-element probability of a sign flip [choose]", Bounds::unit()},
    p.sign_rate);
  v(FieldInfo{"move_rate", "per-element probability of a coordinate move [choose]", Bounds::unit()},
    p.move_rate);
  v(FieldInfo{"move_sigma", "std. dev. of the normally distributed move distance [choose]",
              Bounds::upto(kMaxLength)},
    p.move_sigma);
  v(FieldInfo{"duplicate_rate", "per-genome probability of duplicating a series [choose]",
              Bounds::unit()},
    p.duplicate_rate);
  v(FieldInfo{"delete_rate", "per-genome probability of deleting a series [choose]",
              Bounds::unit()},
    p.delete_rate);
  v(FieldInfo{"max_series_length", "longest series duplicated or deleted at once [choose]",
              Bounds::closed(1, 1000)},
    p.max_series_length);
  v(FieldInfo{"crossover_points", "cut points of multipoint crossover [choose]",
              Bounds::closed(1, 100)},
    p.crossover_points);
}

/// Affinity weight between two elements at distance d: 10 at d = 0, decaying exponentially, and
/// shifted so that it reaches exactly 0 at the cut-off (continuous, monotone).
[[nodiscard]] double affinity(double distance, const GenomeParams& params);
[[nodiscard]] double distance(const Element& a, const Element& b);

/// A regulatory unit (paper §2.1): a series of promoters followed by a series of genes.
struct RegulatoryUnit {
  std::vector<int> promoters;  ///< element indices
  std::vector<int> genes;      ///< element indices
  friend bool operator==(const RegulatoryUnit&, const RegulatoryUnit&) = default;
};

/// The result of reading a genome in order.
struct GenomeLayout {
  std::vector<RegulatoryUnit> units;
  std::vector<int> inputs;   ///< element indices of special inputs
  std::vector<int> outputs;  ///< element indices of special outputs
};

/// Reads the genome sequentially: a maximal run of promoters immediately followed by a maximal run
/// of genes forms a unit. Special elements stand alone and interrupt runs; promoters not followed
/// by genes, and genes not preceded by promoters, are non-coding.
[[nodiscard]] GenomeLayout parse_units(const Genome& genome);

/// Throws GenomeError naming the element index and field if the genome is malformed.
void validate(const Genome& genome, const GenomeParams& params, std::string_view source = "genome");

/// A random genome as the paper seeds it: `initial_units` units of one promoter and one gene, with
/// one special element per enabled input and output channel (enabled_input_channels,
/// enabled_output_channels) inserted at random places between units.
[[nodiscard]] Genome random_genome(const GenomeParams& params, Rng& rng);

// Genetic operators (paper §5). Each keeps the genome valid; each returns how many changes it made.
/// A new special element gets a channel drawn uniformly from the enabled channels of `params`
/// (the overload without params: the paper's channels).
int mutate_types(Genome& g, const MutationParams& m, Rng& rng);
int mutate_types(Genome& g, const MutationParams& m, const GenomeParams& params, Rng& rng);
int mutate_signs(Genome& g, const MutationParams& m, Rng& rng);
int mutate_coordinates(Genome& g, const MutationParams& m, Rng& rng);
/// Copies elements [start, start+length) and inserts the copy right after the series.
void duplicate_series(Genome& g, std::size_t start, std::size_t length);
/// Removes elements [start, start+length).
void delete_series(Genome& g, std::size_t start, std::size_t length);
/// Applies every operator at its rate; duplication never grows past params.max_elements.
int mutate(Genome& g, const MutationParams& m, const GenomeParams& params, Rng& rng);
/// Multipoint crossover: cut points drawn in [0, min(|a|,|b|)], the same in both parents, segments
/// taken alternately starting from `a`; the tail comes from whichever parent is current.
/// Identical parents give the same genome.
[[nodiscard]] Genome crossover(const Genome& a, const Genome& b, int points, Rng& rng);

// JSON form: {"format": "animat.genome", "version": 1, "dimensions": N, "elements": [...]}.
inline constexpr int kGenomeFormatVersion = 1;
[[nodiscard]] std::string to_json(const Genome& genome, int indent = -1);
/// Parses and validates; `source` names the file in errors.
[[nodiscard]] Genome genome_from_json(std::string_view text, const GenomeParams& params = {},
                                      std::string_view source = "<string>");
[[nodiscard]] Genome load_genome(const std::filesystem::path& path,
                                 const GenomeParams& params = {});
void save_genome(const Genome& genome, const std::filesystem::path& path);

/// Stable 64-bit content hash (FNV-1a over every field's bits): equal genomes, equal hashes.
[[nodiscard]] std::uint64_t genome_hash(const Genome& genome);

[[nodiscard]] std::string_view element_type_name(ElementType t);
[[nodiscard]] std::string_view channel_name(const Element& e);

}  // namespace animat
