// GRN (include/animat/grn.hpp, docs/model.md §1, paper eq. 1): edges from affinities, the
// relaxation ΔL = (tanh(max(A,0)/2) − L)·Δt against its closed form, levels in [0, 1), inputs
// (bias, maternal, sensed morphogens), reachability (viability criterion 1) and the DOT export.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "animat/genome.hpp"
#include "animat/grn.hpp"
#include "animat/random.hpp"

using namespace animat;

namespace {

constexpr auto P = ElementType::promoter;
constexpr auto G = ElementType::internal_gene;
constexpr auto M = ElementType::morphogen_gene;

Element el(ElementType t, double x, double y, int sign = 1, int channel = 0) {
  return Element{t, sign, channel, {x, y}};
}
Element in(InputChannel c, double x, double y, int sign = 1) {
  return Element{ElementType::input, sign, static_cast<int>(c), {x, y}};
}
Element out(OutputChannel c, double x, double y, int sign = 1) {
  return Element{ElementType::output, sign, static_cast<int>(c), {x, y}};
}
Genome genome(std::vector<Element> els) { return Genome{2, std::move(els)}; }

// Source indices as documented: 0-3 inputs, 4+u internal product of unit u, 4+U+u diffusible
// product.
int internal_src(int u) { return kPaperInputCount + u; }
int diffusible_src(const Grn& g, int u) { return kPaperInputCount + g.unit_count() + u; }

double weight(const Grn& g, int source, int target) {
  double w = 0.0;
  int found = 0;
  for (const auto& e : g.edges())
    if (e.source == source && e.target == target) {
      w = e.weight;
      ++found;
    }
  EXPECT_LE(found, 1) << "duplicate edge " << source << "->" << target;
  return found ? w : std::numeric_limits<double>::quiet_NaN();
}
bool has_edge(const Grn& g, int source, int target) {
  for (const auto& e : g.edges())
    if (e.source == source && e.target == target) return true;
  return false;
}

// Runs `steps` steps and returns the trajectory of node `node` (k = 0..steps).
std::vector<double> trajectory(const Grn& g, int node, int steps, const GrnInputs& inputs = {},
                               double dt = 0.05) {
  GrnState s = g.initial_state();
  GrnParams p;
  p.dt = dt;
  std::vector<double> out{s.levels[static_cast<std::size_t>(node)]};
  for (int k = 0; k < steps; ++k) {
    g.step(s, inputs, p);
    out.push_back(s.levels[static_cast<std::size_t>(node)]);
  }
  return out;
}

void expect_closed_form(const std::vector<double>& L, double T, double dt,
                        const std::string& what) {
  for (std::size_t k = 0; k < L.size(); ++k) {
    const double expected = T * (1.0 - std::pow(1.0 - dt, static_cast<double>(k)));
    EXPECT_NEAR(L[k], expected, 1e-12) << what << ", step " << k;
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Structure

TEST(GrnStructure, NodesAreUnitsThenOutputs) {
  const Genome g = genome({in(InputChannel::bias, 0, 0), el(P, 0, 0), el(G, 9, 9), el(P, 5, 5),
                           el(M, 5, 5), out(OutputChannel::divide, 9, 9)});
  const Grn grn(g, GenomeParams{});
  EXPECT_EQ(grn.unit_count(), 2);
  EXPECT_EQ(grn.node_count(), 2 + kPaperOutputCount);  // no extension output: the paper's 6
  EXPECT_EQ(grn.output_node(OutputChannel::divide), 2);
  EXPECT_EQ(grn.output_node(OutputChannel::phase), 7);
  EXPECT_EQ(grn.source_count(), kInputCount + 4);
  EXPECT_EQ(grn.morphogen_units(), std::vector<int>{1});
  const GrnState s = grn.initial_state();
  EXPECT_EQ(s.levels, std::vector<double>(8, 0.0));
}

TEST(GrnStructure, EmptyGenome) {
  const Grn grn(Genome{}, GenomeParams{});
  EXPECT_EQ(grn.unit_count(), 0);
  EXPECT_EQ(grn.node_count(), kPaperOutputCount);
  EXPECT_TRUE(grn.edges().empty());
  EXPECT_FALSE(grn.has_required_paths());
  GrnState s = grn.initial_state();
  grn.step(s, {}, GrnParams{});
  EXPECT_EQ(s.levels, std::vector<double>(6, 0.0));
}

TEST(GrnStructure, EdgeWeightIsSumOfAffinityTimesSignProducts) {
  GenomeParams p;
  // Unit 0: promoters at distance 0 and 1 from the bias; unit 1's promoter is inhibited by a
  // negative maternal0 input at distance 0.5; gene of unit 0 at distance 1.5 from the divide
  // output.
  const Genome g =
      genome({in(InputChannel::bias, 0, 0), in(InputChannel::maternal0, 20, 0.5, -1), el(P, 0, 0),
              el(P, 1, 0), el(G, 10, 10), el(P, 20, 0), el(G, 30, 30),
              out(OutputChannel::divide, 10, 11.5), out(OutputChannel::rotate, 30, 30, -1)});
  const Grn grn(g, p);
  ASSERT_EQ(grn.unit_count(), 2);
  EXPECT_NEAR(weight(grn, 0, 0), 10.0 + affinity(1.0, p), 1e-12);
  EXPECT_NEAR(weight(grn, 1, 1), -affinity(0.5, p), 1e-12);
  EXPECT_NEAR(weight(grn, internal_src(0), grn.output_node(OutputChannel::divide)),
              affinity(1.5, p), 1e-12);
  EXPECT_EQ(weight(grn, internal_src(1), grn.output_node(OutputChannel::rotate)), -10.0);
  EXPECT_EQ(grn.edges().size(), 4u);
  // Edges beyond the cut-off do not exist; inputs and outputs are never targets/sources
  // respectively.
  EXPECT_FALSE(has_edge(grn, 0, 1));
  for (const auto& e : grn.edges()) {
    EXPECT_LT(e.target, grn.node_count());
    EXPECT_LT(e.source, grn.source_count());
  }
}

TEST(GrnStructure, SignIsTheProductOfBothSigns) {
  for (int si : {1, -1}) {
    for (int sp : {1, -1}) {
      const Grn grn(genome({in(InputChannel::bias, 0, 0, si), el(P, 0, 0, sp), el(G, 9, 9)}),
                    GenomeParams{});
      EXPECT_EQ(weight(grn, 0, 0), 10.0 * si * sp);
    }
  }
}

TEST(GrnStructure, OutputsAreAcceptorsNotProducts) {
  // An output next to a promoter regulates nothing; an input next to an output drives it.
  const Grn grn(genome({out(OutputChannel::grow, 0, 0), el(P, 0, 0), el(G, 9, 9),
                        in(InputChannel::maternal2, 9, 9)}),
                GenomeParams{});
  EXPECT_EQ(grn.edges().size(), 0u)
      << "gene at (9,9) and maternal2 at (9,9) have no acceptor near them";
  const Grn grn2(genome({out(OutputChannel::grow, 0, 0), in(InputChannel::maternal2, 0, 0)}),
                 GenomeParams{});
  ASSERT_EQ(grn2.edges().size(), 1u);
  EXPECT_EQ(grn2.edges()[0].source, 3);
  EXPECT_EQ(grn2.edges()[0].target, grn2.output_node(OutputChannel::grow));
}

TEST(GrnStructure, NetworkKeyIsWhatTheNetworkReads) {
  const GenomeParams p;
  // bias -> unit 0 (promoter at distance 1) -> divide (gene at distance 1.5); the gene at (30, 30)
  // and the maternal1 input at (50, 0) are beyond the cut-off of every partner.
  auto make = [](double gene_x, double input_x, double promoter_x) {
    return genome({in(InputChannel::bias, 0, 0), el(P, promoter_x, 0), el(G, 10, 10), el(P, 20, 20),
                   el(G, gene_x, 30), in(InputChannel::maternal1, input_x, 0),
                   out(OutputChannel::divide, 10, 11.5)});
  };
  const std::string key = Grn(make(30, 50, 1), p).network_key();
  // a different genome, the same network: elements that take part in no interaction moved
  EXPECT_EQ(Grn(make(33, 50, 1), p).network_key(), key);
  EXPECT_EQ(Grn(make(30, 58, 1), p).network_key(), key);
  // a weight changed (the promoter moved within the cut-off), or an edge gained: another key
  EXPECT_NE(Grn(make(30, 50, 1.25), p).network_key(), key);
  EXPECT_NE(Grn(make(30, 1, 1), p).network_key(), key);
  // a weight's sign, and the kind of a gene (internal against morphogen), are read too
  Genome flipped = make(30, 50, 1);
  flipped.elements[1].sign = -1;
  EXPECT_NE(Grn(flipped, p).network_key(), key);
  Genome morphogen = make(30, 50, 1);
  morphogen.elements[2].type = M;
  EXPECT_NE(Grn(morphogen, p).network_key(), key);
  // an input that regulates nothing is not read: without it, the same key
  Genome without = make(30, 50, 1);
  without.elements.erase(without.elements.begin() + 5);
  EXPECT_EQ(Grn(without, p).network_key(), key);
  // an output without edges is: it decides the number of output nodes
  Genome wider = make(30, 50, 1);
  wider.elements.push_back(out(OutputChannel::stiffness, 90, 90));
  EXPECT_NE(Grn(wider, p).network_key(), key);
}

TEST(GrnStructure, MorphogenUnitsAndProductSources) {
  // Units: 0 internal only, 1 morphogen only, 2 both kinds, 3 morphogen only.
  const Genome g = genome({el(P, 0, 0), el(G, 1, 1), el(P, 2, 2), el(M, 3, 3), el(P, 4, 4),
                           el(G, 5, 5), el(M, 6, 6), el(P, 7, 7), el(M, 8, 8)});
  GenomeParams p;
  p.affinity_cutoff = 0.1;  // no edges at all: only the structure matters here
  const Grn grn(g, p);
  ASSERT_EQ(grn.unit_count(), 4);
  EXPECT_EQ(grn.morphogen_units(), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(grn.source_kind(0), Grn::SourceKind::input);
  EXPECT_EQ(grn.source_kind(3), Grn::SourceKind::input);
  EXPECT_EQ(grn.source_kind(internal_src(2)), Grn::SourceKind::internal_product);
  EXPECT_EQ(grn.source_kind(diffusible_src(grn, 2)), Grn::SourceKind::diffusible_product);
  EXPECT_EQ(grn.source_unit(internal_src(2)), 2);
  EXPECT_EQ(grn.source_unit(diffusible_src(grn, 3)), 3);
}

// ---------------------------------------------------------------------------------------------------
// Eq. 1 against its closed form

TEST(GrnDynamics, BiasDrivenUnitRelaxesAlongClosedForm) {
  // bias -> promoter at distance 0: A = 10, T = tanh(5); L_k = T (1 - (1 - dt)^k).
  const Grn grn(genome({in(InputChannel::bias, 0, 0), el(P, 0, 0), el(G, 9, 9)}), GenomeParams{});
  const auto L = trajectory(grn, 0, 200);
  expect_closed_form(L, std::tanh(5.0), 0.05, "unit");
  // And the discrete recurrence L_{k+1} = L_k + (T - L_k) dt.
  double l = 0.0;
  for (std::size_t k = 1; k < L.size(); ++k) {
    l += (std::tanh(5.0) - l) * 0.05;
    EXPECT_NEAR(L[k], l, 1e-12);
  }
}

TEST(GrnDynamics, ClosedFormForSeveralActivationsAndSigns) {
  GenomeParams p;
  struct Case {
    double promoter_x;  // distance from the bias
    int sign_in, sign_p;
    double A;
  };
  const Case cases[] = {{0.0, 1, 1, 10.0},
                        {0.0, -1, -1, 10.0},
                        {0.5, 1, 1, affinity(0.5, p)},
                        {1.7, 1, 1, affinity(1.7, p)},
                        {0.0, -1, 1, -10.0},
                        {1.0, 1, -1, -affinity(1.0, p)}};
  for (const Case& c : cases) {
    const Grn grn(genome({in(InputChannel::bias, 0, 0, c.sign_in), el(P, c.promoter_x, 0, c.sign_p),
                          el(G, 9, 9)}),
                  p);
    const double T = std::tanh(std::max(c.A, 0.0) / 2.0);
    expect_closed_form(trajectory(grn, 0, 100), T, 0.05, "A = " + std::to_string(c.A));
  }
}

TEST(GrnDynamics, ClosedFormHoldsForOtherDt) {
  const Grn grn(genome({in(InputChannel::bias, 0, 0), el(P, 0, 0), el(G, 9, 9)}), GenomeParams{});
  for (double dt : {0.01, 0.1, 0.3})
    expect_closed_form(trajectory(grn, 0, 100, {}, dt), std::tanh(5.0), dt, "dt");
}

TEST(GrnDynamics, PromotersOfAUnitSumTheirActivation) {
  // Two promoters at the bias: A = 20.
  const Grn grn(genome({in(InputChannel::bias, 0, 0), el(P, 0, 0), el(P, 0, 0), el(G, 9, 9)}),
                GenomeParams{});
  expect_closed_form(trajectory(grn, 0, 60), std::tanh(10.0), 0.05, "two promoters");
}

TEST(GrnDynamics, OutputNodeRelaxesAlongClosedForm) {
  GenomeParams p;
  const Grn grn(genome({in(InputChannel::bias, 0, 0), out(OutputChannel::divide, 0, 0),
                        out(OutputChannel::phase, 0.8, 0)}),
                p);
  ASSERT_EQ(grn.unit_count(), 0);
  expect_closed_form(trajectory(grn, grn.output_node(OutputChannel::divide), 100), std::tanh(5.0),
                     0.05, "divide");
  expect_closed_form(trajectory(grn, grn.output_node(OutputChannel::phase), 100),
                     std::tanh(affinity(0.8, p) / 2), 0.05, "phase");
  // Outputs that nothing drives stay at 0.
  const auto rot = trajectory(grn, grn.output_node(OutputChannel::rotate), 50);
  for (double x : rot) EXPECT_EQ(x, 0.0);
  GrnState s = grn.initial_state();
  grn.step(s, {}, GrnParams{});
  EXPECT_EQ(grn.output(s, OutputChannel::divide),
            s.levels[static_cast<std::size_t>(grn.output_node(OutputChannel::divide))]);
}

TEST(GrnDynamics, UpdateIsSynchronousThroughAChain) {
  // bias -> unit 0 (A=10); unit 0's internal product -> divide (weight 10). Divide's activation at
  // step k uses unit 0's level before step k.
  const Grn grn(genome({in(InputChannel::bias, 0, 0), el(P, 0, 0), el(G, 5, 5),
                        out(OutputChannel::divide, 5, 5)}),
                GenomeParams{});
  GrnState s = grn.initial_state();
  const int d = grn.output_node(OutputChannel::divide);
  double u = 0.0, o = 0.0;
  for (int k = 0; k < 300; ++k) {
    const double u_next = u + (std::tanh(5.0) - u) * 0.05;
    const double o_next = o + (std::tanh(10.0 * u / 2.0) - o) * 0.05;
    u = u_next;
    o = o_next;
    grn.step(s, {}, GrnParams{});
    ASSERT_NEAR(s.levels[0], u, 1e-12) << k;
    ASSERT_NEAR(s.levels[static_cast<std::size_t>(d)], o, 1e-12) << k;
  }
  EXPECT_EQ(s.levels[static_cast<std::size_t>(d)] > 0.0, true);
}

TEST(GrnDynamics, SelfInhibitionDecaysToZero) {
  // A unit whose own product inhibits it, started from a high level, relaxes to 0 as (1-dt)^k.
  const Grn grn(genome({el(P, 0, 0, -1), el(G, 0, 0)}), GenomeParams{});
  ASSERT_EQ(weight(grn, internal_src(0), 0), -10.0);
  GrnState s = grn.initial_state();
  s.levels[0] = 0.8;
  for (int k = 1; k <= 100; ++k) {
    grn.step(s, {}, GrnParams{});
    ASSERT_NEAR(s.levels[0], 0.8 * std::pow(0.95, k), 1e-12);
  }
}

TEST(GrnDynamics, MaternalInputsAreTheirGivenValues) {
  GenomeParams p;
  const Grn grn(genome({in(InputChannel::maternal1, 0, 0), el(P, 0, 0), el(G, 9, 9),
                        in(InputChannel::maternal2, 20, 20), out(OutputChannel::grow, 20, 20.5)}),
                p);
  GrnInputs inputs;
  inputs.maternal = {0.9, 0.3, 0.6};
  expect_closed_form(trajectory(grn, 0, 80, inputs), std::tanh(10.0 * 0.3 / 2), 0.05, "maternal1");
  expect_closed_form(trajectory(grn, grn.output_node(OutputChannel::grow), 80, inputs),
                     std::tanh(affinity(0.5, p) * 0.6 / 2), 0.05, "maternal2");
  inputs.maternal = {0.0, 0.0, 0.0};
  for (double x : trajectory(grn, 0, 20, inputs)) EXPECT_EQ(x, 0.0);
}

TEST(GrnDynamics, DiffusibleProductUsesSensedMorphogensWhenGiven) {
  // Unit 0 (bias-driven) makes a morphogen at (5,5) that activates unit 1's promoter at (5,5).
  const Genome g =
      genome({in(InputChannel::bias, 0, 0), el(P, 0, 0), el(M, 5, 5), el(P, 5, 5), el(G, 9, 0)});
  const Grn grn(g, GenomeParams{});
  ASSERT_EQ(grn.unit_count(), 2);
  ASSERT_EQ(grn.morphogen_units(), std::vector<int>{0});
  EXPECT_EQ(weight(grn, diffusible_src(grn, 0), 1), 10.0);
  // Given a sensed concentration of 0.4, unit 1 sees A = 4 from the first step, whatever unit 0
  // does.
  const std::vector<double> sensed{0.4};
  GrnInputs inputs;
  inputs.morphogens = sensed;
  expect_closed_form(trajectory(grn, 1, 100, inputs), std::tanh(2.0), 0.05, "sensed morphogen");
  // Without sensed values the cell's own level of unit 0 is used (synchronously).
  GrnState s = grn.initial_state();
  double u0 = 0.0, u1 = 0.0;
  for (int k = 0; k < 100; ++k) {
    const double n0 = u0 + (std::tanh(5.0) - u0) * 0.05;
    const double n1 = u1 + (std::tanh(10.0 * u0 / 2) - u1) * 0.05;
    u0 = n0;
    u1 = n1;
    grn.step(s, {}, GrnParams{});
    ASSERT_NEAR(s.levels[1], u1, 1e-12) << k;
  }
}

TEST(GrnDynamics, InternalAndDiffusibleProductsOfOneUnitAreSeparateSources) {
  // Unit 0 has an internal gene at (5,5) and a morphogen gene at (9,0); unit 1's promoter sits at
  // (5,5) (internal product), unit 2's at (9,0) (diffusible product).
  const Genome g = genome({in(InputChannel::bias, 0, 0), el(P, 0, 0), el(G, 5, 5), el(M, 9, 0),
                           el(P, 5, 5), el(G, 20, 20), el(P, 9, 0), el(G, 30, 30)});
  const Grn grn(g, GenomeParams{});
  ASSERT_EQ(grn.unit_count(), 3);
  EXPECT_EQ(weight(grn, internal_src(0), 1), 10.0);
  EXPECT_EQ(weight(grn, diffusible_src(grn, 0), 2), 10.0);
  EXPECT_FALSE(has_edge(grn, diffusible_src(grn, 0), 1));
  const std::vector<double> sensed{0.0};
  GrnInputs inputs;
  inputs.morphogens = sensed;
  GrnState s = grn.initial_state();
  for (int k = 0; k < 200; ++k) grn.step(s, inputs, GrnParams{});
  EXPECT_GT(s.levels[1], 0.5);  // driven by the cell's own internal product
  EXPECT_EQ(s.levels[2], 0.0);  // the sensed morphogen is 0
}

// ---------------------------------------------------------------------------------------------------
// Levels stay in [0, 1)

namespace {

void expect_levels_in_unit_interval(const Grn& grn, const GrnInputs& inputs, int steps, double dt,
                                    const std::string& what) {
  GrnState s = grn.initial_state();
  GrnParams p;
  p.dt = dt;
  for (int k = 0; k < steps; ++k) {
    grn.step(s, inputs, p);
    for (std::size_t i = 0; i < s.levels.size(); ++i) {
      ASSERT_GE(s.levels[i], 0.0) << what << " step " << k << " node " << i;
      ASSERT_LT(s.levels[i], 1.0) << what << " step " << k << " node " << i << " dt " << dt;
    }
  }
}

// 40 bias inputs on top of 40 promoters, and all outputs there: A = ±16000.
Genome extreme_genome(int sign) {
  std::vector<Element> els;
  for (int i = 0; i < 40; ++i) els.push_back(in(InputChannel::bias, 0, 0, sign));
  for (int i = 0; i < 40; ++i) els.push_back(el(P, 0, 0));
  els.push_back(el(G, 0, 0, sign));
  els.push_back(el(M, 0, 0, sign));
  for (int c = 0; c < kOutputCount; ++c) els.push_back(out(static_cast<OutputChannel>(c), 0, 0));
  return genome(els);
}

}  // namespace

TEST(GrnBounds, ExtremePositiveAndNegativeWeightsForLongRuns) {
  for (int sign : {1, -1}) {
    const Grn grn(extreme_genome(sign), GenomeParams{});
    EXPECT_EQ(std::abs(weight(grn, 0, 0)), 16000.0);
    expect_levels_in_unit_interval(grn, {}, 100000, 0.05, sign > 0 ? "positive" : "negative");
  }
}

TEST(GrnBounds, DenseRandomNetworksWithRandomInputsForLongRuns) {
  GenomeParams p;
  p.coord_range = 0.3;  // everything within the cut-off of everything: huge mixed-sign weights
  p.initial_units = 30;
  for (std::uint64_t seed = 0; seed < 3; ++seed) {
    Rng rng(seed);
    const Genome g = random_genome(p, rng);
    const Grn grn(g, p);
    GrnInputs inputs;
    inputs.maternal = {rng.uniform(), rng.uniform(), rng.uniform()};
    std::vector<double> sensed(grn.morphogen_units().size());
    for (double& x : sensed) x = rng.uniform();
    inputs.morphogens = sensed;
    expect_levels_in_unit_interval(grn, inputs, 100000, 0.05, "seed " + std::to_string(seed));
  }
}

TEST(GrnBounds, LevelsStayBelowOneForEveryAllowedDt) {
  // grn.dt is allowed in (0, 1]. tanh(A/2) rounds to exactly 1.0 for A >~ 38, so the [0, 1)
  // invariant must not depend on dt being small.
  const Grn grn(extreme_genome(1), GenomeParams{});
  for (double dt : {0.05, 0.1, 0.25, 0.5, 0.9, 1.0})
    expect_levels_in_unit_interval(grn, {}, 2000, dt, "extreme");
}

// ---------------------------------------------------------------------------------------------------
// Reachability (viability criterion 1)

namespace {

std::vector<Element> all_required_outputs(double x, double y) {
  return {out(OutputChannel::divide, x, y), out(OutputChannel::amplitude, x, y),
          out(OutputChannel::frequency, x, y), out(OutputChannel::phase, x, y)};
}

}  // namespace

TEST(GrnPaths, DirectPathFromBias) {
  std::vector<Element> els{in(InputChannel::bias, 0, 0)};
  for (auto& e : all_required_outputs(0, 0)) els.push_back(e);
  const Grn grn(genome(els), GenomeParams{});
  EXPECT_TRUE(grn.has_required_paths());
  EXPECT_TRUE(grn.reaches(OutputChannel::divide));
  EXPECT_FALSE(grn.reaches(OutputChannel::rotate));  // not present, and not required
  EXPECT_FALSE(grn.reaches(OutputChannel::grow));
}

TEST(GrnPaths, EachRequiredOutputIsNeeded) {
  for (OutputChannel missing : {OutputChannel::divide, OutputChannel::amplitude,
                                OutputChannel::frequency, OutputChannel::phase}) {
    std::vector<Element> els{in(InputChannel::maternal0, 0, 0)};
    for (auto& e : all_required_outputs(0, 0)) {
      if (e.channel == static_cast<int>(missing)) e.coords = {50, 50};  // out of reach
      els.push_back(e);
    }
    const Grn grn(genome(els), GenomeParams{});
    EXPECT_FALSE(grn.has_required_paths()) << "missing " << static_cast<int>(missing);
    EXPECT_FALSE(grn.reaches(missing));
  }
}

TEST(GrnPaths, RotateAndGrowAreNotRequired) {
  std::vector<Element> els{in(InputChannel::bias, 0, 0), out(OutputChannel::rotate, 50, 50),
                           out(OutputChannel::grow, 60, 60)};
  for (auto& e : all_required_outputs(0, 0)) els.push_back(e);
  const Grn grn(genome(els), GenomeParams{});
  EXPECT_TRUE(grn.has_required_paths());
  EXPECT_FALSE(grn.reaches(OutputChannel::rotate));
}

TEST(GrnPaths, PathThroughIntermediateUnits) {
  // bias -> unit 0 -> unit 1 (via internal product) -> outputs; no direct bias->output edge.
  std::vector<Element> els{in(InputChannel::bias, 0, 0), el(P, 0, 0), el(G, 5, 5), el(P, 5, 5),
                           el(G, 10, 10)};
  for (auto& e : all_required_outputs(10, 10)) els.push_back(e);
  const Grn grn(genome(els), GenomeParams{});
  ASSERT_EQ(grn.unit_count(), 2);
  EXPECT_FALSE(has_edge(grn, 0, grn.output_node(OutputChannel::divide)));
  EXPECT_TRUE(grn.has_required_paths());

  // Through a diffusible product as well.
  std::vector<Element> els2{in(InputChannel::bias, 0, 0), el(P, 0, 0), el(M, 5, 5), el(P, 5, 5),
                            el(G, 10, 10)};
  for (auto& e : all_required_outputs(10, 10)) els2.push_back(e);
  EXPECT_TRUE(Grn(genome(els2), GenomeParams{}).has_required_paths());

  // Break the chain: unit 1's promoter moves away from unit 0's product.
  els[3].coords = {30, 30};
  EXPECT_FALSE(Grn(genome(els), GenomeParams{}).has_required_paths());
  // Break the parse: the gene of unit 0 is separated from its promoter by a special element.
  std::vector<Element> els3{in(InputChannel::bias, 0, 0),
                            el(P, 0, 0),
                            out(OutputChannel::rotate, 40, 40),
                            el(G, 5, 5),
                            el(P, 5, 5),
                            el(G, 10, 10)};
  for (auto& e : all_required_outputs(10, 10)) els3.push_back(e);
  EXPECT_FALSE(Grn(genome(els3), GenomeParams{}).has_required_paths());
}

TEST(GrnPaths, UnitsDrivingOutputsButUnreachedFromInputsDoNotCount) {
  // A self-activating unit drives all outputs, but no input reaches it.
  std::vector<Element> els{in(InputChannel::bias, 40, 40), el(P, 0, 0), el(G, 0, 0)};
  for (auto& e : all_required_outputs(0, 0)) els.push_back(e);
  const Grn grn(genome(els), GenomeParams{});
  EXPECT_TRUE(has_edge(grn, internal_src(0), grn.output_node(OutputChannel::divide)));
  EXPECT_FALSE(grn.has_required_paths());
  // Without any input element at all.
  els.erase(els.begin());
  EXPECT_FALSE(Grn(genome(els), GenomeParams{}).has_required_paths());
}

TEST(GrnPaths, CyclesTerminateAndInhibitoryEdgesArePaths) {
  // bias -| unit 0 <-> unit 1 -> outputs
  std::vector<Element> els{in(InputChannel::bias, 0, 0, -1), el(P, 0, 0), el(G, 5, 5), el(P, 5, 5),
                           el(G, 0.5, 0)};
  for (auto& e : all_required_outputs(5, 5)) els.push_back(e);
  const Grn grn(genome(els), GenomeParams{});
  EXPECT_LT(weight(grn, 0, 0), 0.0);
  EXPECT_TRUE(grn.has_required_paths());
}

TEST(GrnPaths, CutoffFromConfigDecidesReachability) {
  std::vector<Element> els{in(InputChannel::bias, 0, 0)};
  for (auto& e : all_required_outputs(1.5, 0)) els.push_back(e);
  GenomeParams wide, narrow;
  narrow.affinity_cutoff = 1.0;
  EXPECT_TRUE(Grn(genome(els), wide).has_required_paths());
  EXPECT_FALSE(Grn(genome(els), narrow).has_required_paths());
}

// ---------------------------------------------------------------------------------------------------
// DOT export

TEST(GrnDot, ContainsNodesAndEdges) {
  const Genome g = genome({in(InputChannel::bias, 0, 0), el(P, 0, 0), el(M, 5, 5), el(P, 5, 5, -1),
                           el(G, 10, 10), out(OutputChannel::divide, 10, 10)});
  const Grn grn(g, GenomeParams{});
  const std::string dot = grn.to_dot();
  EXPECT_EQ(dot.rfind("digraph", 0), 0u) << dot;
  EXPECT_EQ(dot.back(), '\n');
  EXPECT_NE(dot.find("}"), std::string::npos);
  for (const char* s :
       {"in0 [label=\"bias\"", "in3 [label=\"maternal2\"", "u0 [label=\"unit 0 (morphogen)\"]",
        "u1 [label=\"unit 1\"]", "out0 [label=\"divide\"", "out5 [label=\"phase\"",
        "in0 -> u0 [label=\"10\", color=black]",
        "u0 -> u1 [label=\"-10\", color=red, style=dashed]",
        "u1 -> out0 [label=\"10\", color=black]"})
    EXPECT_NE(dot.find(s), std::string::npos) << "missing " << s << " in\n" << dot;
  std::size_t arrows = 0;
  for (std::size_t pos = dot.find("->"); pos != std::string::npos; pos = dot.find("->", pos + 2))
    ++arrows;
  EXPECT_EQ(arrows, grn.edges().size());
  EXPECT_EQ(arrows, 3u);
}

// --- Extension channels (docs/model.md "Genome channels") ----------------------------------------

TEST(GrnChannels, PaperGenomesKeepSixOutputNodesExtensionOutputsAddTwo) {
  const Grn paper(genome({in(InputChannel::bias, 0, 0), out(OutputChannel::divide, 0, 0)}),
                  GenomeParams{});
  EXPECT_EQ(paper.output_count(), kPaperOutputCount);
  EXPECT_EQ(paper.node_count(), kPaperOutputCount);
  EXPECT_EQ(paper.output(paper.initial_state(), OutputChannel::actuation), 0.0);
  const Grn ext(genome({in(InputChannel::bias, 0, 0), el(P, 0, 0), el(G, 9, 9),
                        out(OutputChannel::actuation, 0, 0)}),
                GenomeParams{});
  EXPECT_EQ(ext.output_count(), kOutputCount);
  EXPECT_EQ(ext.node_count(), 1 + kOutputCount);
  EXPECT_EQ(ext.output_node(OutputChannel::actuation), 1 + 7);
  EXPECT_TRUE(ext.reaches(OutputChannel::actuation));
}

TEST(GrnChannels, SensorInputsComeAfterTheProductsAndFollowTheirValue) {
  // strain -> actuation at distance 0: weight 10, A = 10·strain, level -> tanh(5·strain).
  const Grn grn(genome({el(P, 5, 5), el(G, 9, 9), in(InputChannel::strain, 0, 0),
                        out(OutputChannel::actuation, 0, 0)}),
                GenomeParams{});
  ASSERT_EQ(grn.unit_count(), 1);
  ASSERT_EQ(grn.edges().size(), 1u);
  const auto& e = grn.edges()[0];
  EXPECT_EQ(e.source, kPaperInputCount + 2 * 1 + 0);  // after internal and diffusible products
  EXPECT_EQ(grn.source_kind(e.source), Grn::SourceKind::input);
  EXPECT_EQ(grn.source_unit(e.source), static_cast<int>(InputChannel::strain));
  EXPECT_EQ(e.weight, 10.0);
  GrnState s = grn.initial_state();
  GrnInputs inputs;
  inputs.sensors[0] = 0.1;
  GrnParams gp;
  double expected = 0.0;
  for (int k = 0; k < 50; ++k) {
    grn.step(s, inputs, gp);
    expected += (std::tanh(10.0 * 0.1 / 2) - expected) * gp.dt;
  }
  EXPECT_NEAR(grn.output(s, OutputChannel::actuation), expected, 1e-15);
  EXPECT_NE(grn.to_dot().find("in4 [label=\"strain\""), std::string::npos);
  EXPECT_NE(grn.to_dot().find("in4 -> out7"), std::string::npos);
}
