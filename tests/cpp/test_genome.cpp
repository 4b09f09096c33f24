// Genome (include/animat/genome.hpp, docs/model.md §1): affinity, parsing into regulatory units,
// validation, the random genome, genetic operators, JSON round trips and rejection of bad JSON.
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/genome.hpp"
#include "animat/random.hpp"

using namespace animat;
namespace fs = std::filesystem;

namespace {

constexpr auto P = ElementType::promoter;
constexpr auto G = ElementType::internal_gene;
constexpr auto M = ElementType::morphogen_gene;
constexpr auto I = ElementType::input;
constexpr auto O = ElementType::output;

// Elements of a hand-built genome get distinct coordinates (x = index) so that they can be told
// apart.
Genome make(std::initializer_list<ElementType> types) {
  Genome g;
  g.dimensions = 2;
  double x = 0.0;
  for (ElementType t : types) {
    g.elements.push_back(Element{t, 1, 0, {x, 0.5 * x}});
    x += 1.0;
  }
  return g;
}

std::vector<RegulatoryUnit> units(
    std::initializer_list<std::pair<std::vector<int>, std::vector<int>>> list) {
  std::vector<RegulatoryUnit> out;
  for (const auto& [p, g] : list) out.push_back(RegulatoryUnit{p, g});
  return out;
}

std::string message_of(const auto& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "<no exception>";
}

fs::path bad_input(const std::string& name) {
  return fs::path(ANIMAT_SOURCE_DIR) / "tests" / "bad_inputs" / name;
}

fs::path temp_path(const std::string& name) {
  // Per process: ctest runs tests in parallel, and other build trees may run the same tests.
  return fs::temp_directory_path() /
         ("animat_test_genome_" + std::to_string(::getpid()) + "_" + name);
}

bool bit_equal(const Genome& a, const Genome& b) {
  if (a.dimensions != b.dimensions || a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Element &x = a.elements[i], &y = b.elements[i];
    if (x.type != y.type || x.sign != y.sign || x.channel != y.channel ||
        x.coords.size() != y.coords.size())
      return false;
    for (std::size_t k = 0; k < x.coords.size(); ++k)
      if (std::bit_cast<std::uint64_t>(x.coords[k]) != std::bit_cast<std::uint64_t>(y.coords[k]))
        return false;
  }
  return true;
}

Genome random_with(std::uint64_t seed, const GenomeParams& p = {}) {
  Rng rng(seed);
  return random_genome(p, rng);
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Affinity

TEST(Affinity, TenAtZeroDistanceForDefaults) { EXPECT_EQ(affinity(0.0, GenomeParams{}), 10.0); }

TEST(Affinity, ExactlyTenAtZeroDistanceForEveryDecayAndCutoff) {
  // "Affinity weight: 10 at distance 0" must hold for every configured decay and cut-off, exactly.
  int wrong = 0;
  std::string first;
  for (double decay : {0.1, 0.25, 0.5, 0.7, 1.0, 1.5, 2.0, 2.5, 3.0, 5.0, 10.0}) {
    for (double cutoff : {0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 10.0}) {
      GenomeParams p;
      p.affinity_decay = decay;
      p.affinity_cutoff = cutoff;
      const double a = affinity(0.0, p);
      if (a != 10.0) {
        if (wrong++ == 0)
          first = "decay " + std::to_string(decay) + ", cutoff " + std::to_string(cutoff);
      }
    }
  }
  EXPECT_EQ(wrong, 0) << "affinity(0) != 10 exactly, first for " << first;
  GenomeParams p;
  p.affinity_decay = 0.5;
  p.affinity_cutoff = 0.5;
  EXPECT_EQ(affinity(0.0, p), 10.0)
      << "decay 0.5, cutoff 0.5: affinity(0) = " << std::setprecision(17) << affinity(0.0, p);
}

TEST(Affinity, MatchesShiftedExponentialClosedForm) {
  const GenomeParams p;  // decay 1, cutoff 2
  const double tail = std::exp(-2.0);
  for (double d : {0.1, 0.5, 1.0, 1.5, 1.9}) {
    const double expected = 10.0 * (std::exp(-d) - tail) / (1.0 - tail);
    EXPECT_NEAR(affinity(d, p), expected, 1e-12) << "d = " << d;
  }
  EXPECT_NEAR(affinity(1.0, p), 10.0 * (std::exp(-1.0) - std::exp(-2.0)) / (1.0 - std::exp(-2.0)),
              1e-12);
}

TEST(Affinity, StrictlyDecreasingBelowCutoffAndPositive) {
  for (double decay : {0.2, 1.0, 3.0}) {
    for (double cutoff : {0.5, 2.0, 7.0}) {
      GenomeParams p;
      p.affinity_decay = decay;
      p.affinity_cutoff = cutoff;
      double prev = affinity(0.0, p);
      const int n = 2000;
      for (int i = 1; i < n; ++i) {
        const double d = cutoff * i / n;
        const double a = affinity(d, p);
        ASSERT_LT(a, prev) << "decay " << decay << " cutoff " << cutoff << " d " << d;
        ASSERT_GT(a, 0.0) << "decay " << decay << " cutoff " << cutoff << " d " << d;
        prev = a;
      }
    }
  }
}

TEST(Affinity, ExactlyZeroAtAndBeyondCutoffAndContinuousThere) {
  for (double decay : {0.2, 1.0, 3.0}) {
    for (double cutoff : {0.5, 2.0, 7.0}) {
      GenomeParams p;
      p.affinity_decay = decay;
      p.affinity_cutoff = cutoff;
      EXPECT_EQ(affinity(cutoff, p), 0.0);
      EXPECT_EQ(affinity(std::nextafter(cutoff, 1e9), p), 0.0);
      EXPECT_EQ(affinity(cutoff * 1.5, p), 0.0);
      EXPECT_EQ(affinity(1e300, p), 0.0);
      EXPECT_EQ(affinity(std::numeric_limits<double>::infinity(), p), 0.0);
      const double just_below = affinity(cutoff * (1 - 1e-9), p);
      EXPECT_GE(just_below, 0.0);
      EXPECT_LT(just_below, 1e-6);  // continuous at the cut-off: no jump
    }
  }
}

TEST(Affinity, RespectsConfiguredDecayAndCutoff) {
  GenomeParams slow, fast, short_cut;
  slow.affinity_decay = 0.5;
  fast.affinity_decay = 3.0;
  short_cut.affinity_cutoff = 1.0;
  EXPECT_GT(affinity(1.0, slow), affinity(1.0, GenomeParams{}));
  EXPECT_LT(affinity(1.0, fast), affinity(1.0, GenomeParams{}));
  EXPECT_GT(affinity(1.5, GenomeParams{}), 0.0);
  EXPECT_EQ(affinity(1.5, short_cut), 0.0);
  EXPECT_EQ(affinity(1.0, short_cut), 0.0);
  // closed form with decay 3, cutoff 2
  const double tail = std::exp(-6.0);
  EXPECT_NEAR(affinity(0.4, fast), 10.0 * (std::exp(-1.2) - tail) / (1.0 - tail), 1e-12);
}

TEST(Distance, IsEuclidean) {
  Element a{P, 1, 0, {0.0, 0.0}}, b{G, 1, 0, {3.0, 4.0}};
  EXPECT_EQ(distance(a, b), 5.0);
  EXPECT_EQ(distance(b, a), 5.0);
  Element c{P, 1, 0, {1.0, 2.0, 2.0}}, d{P, 1, 0, {0.0, 0.0, 0.0}};
  EXPECT_EQ(distance(c, d), 3.0);
  EXPECT_EQ(distance(a, a), 0.0);
}

// ---------------------------------------------------------------------------------------------------
// Parsing into regulatory units

TEST(Parse, EmptyGenome) {
  const GenomeLayout l = parse_units(Genome{});
  EXPECT_TRUE(l.units.empty());
  EXPECT_TRUE(l.inputs.empty());
  EXPECT_TRUE(l.outputs.empty());
}

TEST(Parse, OnlyPromotersAreNonCoding) {
  for (auto g : {make({P}), make({P, P}), make({P, P, P, P, P})}) {
    const GenomeLayout l = parse_units(g);
    EXPECT_TRUE(l.units.empty());
    EXPECT_TRUE(l.inputs.empty());
    EXPECT_TRUE(l.outputs.empty());
  }
}

TEST(Parse, OnlyGenesAreNonCoding) {
  for (auto g : {make({G}), make({M}), make({G, M, G, G})})
    EXPECT_TRUE(parse_units(g).units.empty());
}

TEST(Parse, SinglePromoterGene) {
  EXPECT_EQ(parse_units(make({P, G})).units, units({{{0}, {1}}}));
  EXPECT_EQ(parse_units(make({P, M})).units, units({{{0}, {1}}}));
}

TEST(Parse, PPGGPG) {
  EXPECT_EQ(parse_units(make({P, P, G, G, P, G})).units, units({{{0, 1}, {2, 3}}, {{4}, {5}}}));
}

TEST(Parse, GenesOfBothKindsShareAUnit) {
  EXPECT_EQ(parse_units(make({P, G, M, G})).units, units({{{0}, {1, 2, 3}}}));
}

TEST(Parse, LeadingGeneIsNonCoding) {
  EXPECT_EQ(parse_units(make({G, P, G})).units, units({{{1}, {2}}}));
}

TEST(Parse, TrailingStrayPromoters) {
  EXPECT_EQ(parse_units(make({P, G, P, P})).units, units({{{0}, {1}}}));
  EXPECT_TRUE(parse_units(make({P, P})).units.empty());
}

TEST(Parse, PromoterAfterGenesStartsANewUnit) {
  EXPECT_EQ(parse_units(make({P, G, G, P, P, G, M})).units,
            units({{{0}, {1, 2}}, {{3, 4}, {5, 6}}}));
}

TEST(Parse, SpecialBetweenPromoterAndGeneBreaksTheUnit) {
  for (ElementType s : {I, O}) {
    const GenomeLayout l = parse_units(make({P, s, G}));
    EXPECT_TRUE(l.units.empty()) << "special type " << static_cast<int>(s);
  }
  GenomeLayout l = parse_units(make({P, P, I, P, G}));
  EXPECT_EQ(l.units, units({{{3}, {4}}}));
  EXPECT_EQ(l.inputs, std::vector<int>{2});
}

TEST(Parse, SpecialBetweenGenesEndsTheUnit) {
  const GenomeLayout l = parse_units(make({P, G, O, G, P, G}));
  EXPECT_EQ(l.units, units({{{0}, {1}}, {{4}, {5}}}));  // element 3 is a gene without promoters
  EXPECT_EQ(l.outputs, std::vector<int>{2});
  EXPECT_TRUE(l.inputs.empty());
}

TEST(Parse, SpecialElementsEverywhere) {
  // I O P I G O P G I P O G O  : only the P G at 6,7 forms a unit.
  const GenomeLayout l = parse_units(make({I, O, P, I, G, O, P, G, I, P, O, G, O}));
  EXPECT_EQ(l.units, units({{{6}, {7}}}));
  EXPECT_EQ(l.inputs, (std::vector<int>{0, 3, 8}));
  EXPECT_EQ(l.outputs, (std::vector<int>{1, 5, 10, 12}));
}

TEST(Parse, OnlySpecialElements) {
  const GenomeLayout l = parse_units(make({I, I, O, I, O}));
  EXPECT_TRUE(l.units.empty());
  EXPECT_EQ(l.inputs, (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(l.outputs, (std::vector<int>{2, 4}));
}

TEST(Parse, SpecialsAtTheEnds) {
  const GenomeLayout l = parse_units(make({O, P, P, G, M, I}));
  EXPECT_EQ(l.units, units({{{1, 2}, {3, 4}}}));
  EXPECT_EQ(l.inputs, std::vector<int>{5});
  EXPECT_EQ(l.outputs, std::vector<int>{0});
}

// ---------------------------------------------------------------------------------------------------
// Validation

TEST(Validate, AcceptsWellFormedAndRejectsEachDefectNamingIt) {
  Genome ok = make({P, G, I, O});
  ok.elements[2].channel = 3;
  ok.elements[3].channel = 5;
  EXPECT_NO_THROW(validate(ok, GenomeParams{}));

  Genome bad_sign = ok;
  bad_sign.elements[1].sign = 0;
  EXPECT_THROW(validate(bad_sign, GenomeParams{}), GenomeError);
  EXPECT_NE(message_of([&] {
              validate(bad_sign, GenomeParams{}, "g.json");
            }).find("g.json: element 1: sign = 0"),
            std::string::npos);

  Genome bad_input_channel = ok;
  // 0-3 the paper's, 4-6 the extensions (strain, pressure, chemical)
  bad_input_channel.elements[2].channel = 7;
  const std::string m1 = message_of([&] { validate(bad_input_channel, GenomeParams{}); });
  EXPECT_NE(m1.find("element 2"), std::string::npos) << m1;
  EXPECT_NE(m1.find("channel 7 out of range [0, 7)"), std::string::npos) << m1;

  Genome bad_output_channel = ok;
  bad_output_channel.elements[3].channel = 8;  // 0-5 the paper's, 6-7 stiffness and actuation
  EXPECT_NE(message_of([&] {
              validate(bad_output_channel, GenomeParams{});
            }).find("channel 8 out of range [0, 8)"),
            std::string::npos);

  Genome channel_on_promoter = ok;
  channel_on_promoter.elements[0].channel = 1;
  EXPECT_THROW(validate(channel_on_promoter, GenomeParams{}), GenomeError);

  Genome bad_type = ok;
  bad_type.elements[0].type = static_cast<ElementType>(7);
  EXPECT_NE(message_of([&] { validate(bad_type, GenomeParams{}); }).find("unknown type 7"),
            std::string::npos);

  Genome bad_coords = ok;
  bad_coords.elements[1].coords.push_back(1.0);
  EXPECT_NE(
      message_of([&] { validate(bad_coords, GenomeParams{}); }).find("3 coordinates, expected 2"),
      std::string::npos);

  for (double x : {std::nan(""), std::numeric_limits<double>::infinity(),
                   -std::numeric_limits<double>::infinity()}) {
    Genome nonfinite = ok;
    nonfinite.elements[3].coords[1] = x;
    const std::string m = message_of([&] { validate(nonfinite, GenomeParams{}); });
    EXPECT_NE(m.find("element 3: coordinate 1"), std::string::npos) << m;
    EXPECT_NE(m.find("must be finite"), std::string::npos) << m;
  }

  Genome bad_dims = ok;
  bad_dims.dimensions = 0;
  EXPECT_NE(message_of([&] { validate(bad_dims, GenomeParams{}); }).find("dimensions = 0"),
            std::string::npos);

  GenomeParams small;
  small.max_elements = 3;
  EXPECT_NE(
      message_of([&] { validate(ok, small); }).find("4 elements exceed genome.max_elements = 3"),
      std::string::npos);
}

// ---------------------------------------------------------------------------------------------------
// Random genome

TEST(RandomGenome, HasThePaperLayout) {
  for (std::uint64_t seed = 0; seed < 50; ++seed) {
    const GenomeParams p;
    const Genome g = random_with(seed, p);
    ASSERT_NO_THROW(validate(g, p));
    EXPECT_EQ(g.dimensions, 2);
    EXPECT_EQ(g.size(),
              static_cast<std::size_t>(2 * p.initial_units + kPaperInputCount + kPaperOutputCount));
    const GenomeLayout l = parse_units(g);
    ASSERT_EQ(l.units.size(), static_cast<std::size_t>(p.initial_units)) << "seed " << seed;
    for (const auto& u : l.units) {
      EXPECT_EQ(u.promoters.size(), 1u);
      EXPECT_EQ(u.genes.size(), 1u);
    }
    std::set<int> ins, outs;
    for (int i : l.inputs) ins.insert(g.elements[static_cast<std::size_t>(i)].channel);
    for (int o : l.outputs) outs.insert(g.elements[static_cast<std::size_t>(o)].channel);
    EXPECT_EQ(ins, (std::set<int>{0, 1, 2, 3}));
    EXPECT_EQ(outs, (std::set<int>{0, 1, 2, 3, 4, 5}));
    for (const Element& e : g.elements) {
      for (double x : e.coords) {
        EXPECT_GE(x, 0.0);
        EXPECT_LT(x, p.coord_range);
      }
      EXPECT_TRUE(e.sign == 1 || e.sign == -1);
    }
  }
}

TEST(RandomGenome, RespectsDimensionsUnitsAndMorphogenProbability) {
  GenomeParams p;
  p.dimensions = 3;
  p.initial_units = 4;
  p.coord_range = 0.5;
  p.morphogen_gene_probability = 1.0;
  const Genome g = random_with(3, p);
  EXPECT_EQ(g.dimensions, 3);
  EXPECT_EQ(g.size(), 4u * 2 + 10);
  for (const Element& e : g.elements) {
    ASSERT_EQ(e.coords.size(), 3u);
    EXPECT_NE(e.type, G);
    for (double x : e.coords) EXPECT_LT(x, 0.5);
  }
  p.morphogen_gene_probability = 0.0;
  for (const Element& e : random_with(3, p).elements) EXPECT_NE(e.type, M);
}

TEST(RandomGenome, SameSeedSameGenomeDifferentSeedsDiffer) {
  const Genome a = random_with(123), b = random_with(123), c = random_with(124);
  EXPECT_TRUE(bit_equal(a, b));
  EXPECT_EQ(genome_hash(a), genome_hash(b));
  EXPECT_FALSE(a == c);
  EXPECT_NE(genome_hash(a), genome_hash(c));
  // The same stream through Rng::derive.
  Rng r1 = Rng::derive(9, 2, 5), r2 = Rng::derive(9, 2, 5);
  EXPECT_TRUE(bit_equal(random_genome(GenomeParams{}, r1), random_genome(GenomeParams{}, r2)));
}

TEST(RandomGenome, IsValidUnderEveryConfigThatValidates) {
  // A config that passes validate() must not make random_genome produce a genome that
  // validate(genome, params) rejects: the random genome has 2*initial_units + 10 elements.
  Config c;
  c.genome.max_elements = 20;  // in the documented range [1, 1000000]
  bool config_accepted = true;
  try {
    animat::validate(c);
  } catch (const ConfigError&) {
    config_accepted = false;
  }
  if (config_accepted) {
    Rng rng(1);
    const Genome g = random_genome(c.genome, rng);
    EXPECT_NO_THROW(validate(g, c.genome))
        << "config with genome.max_elements = 20 validates, but the random genome has " << g.size()
        << " elements";
  }
}

// ---------------------------------------------------------------------------------------------------
// Operators

TEST(Operators, MutateTypesAtRateOneChangesEveryTypeAndStaysValid) {
  MutationParams m;
  m.type_rate = 1.0;
  for (std::uint64_t seed = 0; seed < 100; ++seed) {
    Genome g = random_with(seed);
    const Genome before = g;
    Rng rng(seed + 1000);
    EXPECT_EQ(mutate_types(g, m, rng), static_cast<int>(g.size()));
    ASSERT_NO_THROW(validate(g, GenomeParams{})) << "seed " << seed;
    for (std::size_t i = 0; i < g.size(); ++i) {
      EXPECT_NE(g.elements[i].type, before.elements[i].type);
      EXPECT_EQ(g.elements[i].sign, before.elements[i].sign);
      EXPECT_EQ(g.elements[i].coords, before.elements[i].coords);
      if (!g.elements[i].is_special()) {
        EXPECT_EQ(g.elements[i].channel, 0);
      }
    }
  }
  Genome g = random_with(1);
  const Genome before = g;
  Rng rng(2);
  m.type_rate = 0.0;
  EXPECT_EQ(mutate_types(g, m, rng), 0);
  EXPECT_TRUE(bit_equal(g, before));
}

TEST(Operators, MutateTypesReachesEveryTypeAndChannel) {
  MutationParams m;
  m.type_rate = 1.0;
  std::set<std::pair<int, int>> seen;  // (type, channel)
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    Genome g = random_with(seed);
    Rng rng(seed);
    mutate_types(g, m, rng);
    for (const Element& e : g.elements) seen.insert({static_cast<int>(e.type), e.channel});
  }
  EXPECT_EQ(seen.size(), 3u + kPaperInputCount + kPaperOutputCount);  // the paper's channels only
}

// --- Extension channels (genome.extra_inputs / extra_outputs, docs/model.md "Genome channels")
// ----

TEST(GenomeChannels, FixedNumbersAndNames) {
  EXPECT_EQ(static_cast<int>(InputChannel::strain), 4);
  EXPECT_EQ(static_cast<int>(InputChannel::pressure), 5);
  EXPECT_EQ(static_cast<int>(InputChannel::chemical), 6);
  EXPECT_EQ(static_cast<int>(OutputChannel::stiffness), 6);
  EXPECT_EQ(static_cast<int>(OutputChannel::actuation), 7);
  EXPECT_EQ(kInputNames[6], "chemical");
  EXPECT_EQ(kOutputNames[6], "stiffness");
  EXPECT_EQ(kOutputNames[7], "actuation");
  EXPECT_EQ(kPaperInputCount, 4);
  EXPECT_EQ(kPaperOutputCount, 6);
}

TEST(GenomeChannels, EnabledListsParseInChannelOrderAndRejectBadNames) {
  GenomeParams p;
  EXPECT_EQ(enabled_input_channels(p), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(enabled_output_channels(p), (std::vector<int>{0, 1, 2, 3, 4, 5}));
  p.extra_inputs = "chemical, strain";
  p.extra_outputs = "actuation";
  EXPECT_EQ(enabled_input_channels(p), (std::vector<int>{0, 1, 2, 3, 4, 6}));
  EXPECT_EQ(enabled_output_channels(p), (std::vector<int>{0, 1, 2, 3, 4, 5, 7}));
  p.extra_outputs = "stiffness,actuation";
  EXPECT_EQ(enabled_output_channels(p), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  for (const char* bad : {"bias", "strain,strain", "strian", "strain,", ",strain"}) {
    p.extra_inputs = bad;
    try {
      (void)enabled_input_channels(p);
      ADD_FAILURE() << bad;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("genome.extra_inputs"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
  Config c;
  c.genome.extra_outputs = "divide";
  try {
    validate(c);
    ADD_FAILURE() << "a paper channel is not an extension";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("genome.extra_outputs = \"divide\""), std::string::npos)
        << e.what();
  }
  apply_override(c, "genome.extra_outputs=actuation");
  EXPECT_NO_THROW(validate(c));
  EXPECT_EQ(std::get<std::string>(get_value(c, "genome.extra_outputs")), "actuation");
}

TEST(GenomeChannels, RandomGenomesAndMutationsDrawOnlyEnabledChannels) {
  GenomeParams p;
  p.extra_inputs = "chemical";
  p.extra_outputs = "actuation";
  MutationParams m;
  m.type_rate = 1.0;
  std::set<int> ins, outs;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    Rng rng(seed);
    Genome g = random_genome(p, rng);
    ASSERT_EQ(g.size(), static_cast<std::size_t>(2 * p.initial_units + 5 + 7));
    const GenomeLayout l = parse_units(g);
    std::set<int> gi, go;
    for (int i : l.inputs) gi.insert(g.elements[static_cast<std::size_t>(i)].channel);
    for (int o : l.outputs) go.insert(g.elements[static_cast<std::size_t>(o)].channel);
    EXPECT_EQ(gi, (std::set<int>{0, 1, 2, 3, 6}));
    EXPECT_EQ(go, (std::set<int>{0, 1, 2, 3, 4, 5, 7}));
    mutate_types(g, m, p, rng);
    for (const Element& e : g.elements) {
      if (e.type == ElementType::input) ins.insert(e.channel);
      if (e.type == ElementType::output) outs.insert(e.channel);
    }
  }
  EXPECT_EQ(ins, (std::set<int>{0, 1, 2, 3, 6}));
  EXPECT_EQ(outs, (std::set<int>{0, 1, 2, 3, 4, 5, 7}));
}

TEST(GenomeChannels, DefaultsDrawExactlyThePapersStream) {
  // With no extension enabled, random genomes and mutations consume the RNG exactly as before:
  // the explicit-params overload equals the paper's one, draw for draw.
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    Rng a(seed), b(seed);
    Genome ga = random_genome(GenomeParams{}, a);
    Genome gb = random_genome(GenomeParams{}, b);
    MutationParams m;
    m.type_rate = 0.3;
    mutate_types(ga, m, a);
    mutate_types(gb, m, GenomeParams{}, b);
    EXPECT_EQ(ga, gb);
    EXPECT_EQ(a(), b());
  }
}

TEST(GenomeChannels, JsonWithExtensionChannelNamesRoundTrips) {
  Genome g = make({I, P, G, O, O});
  g.elements[0].channel = static_cast<int>(InputChannel::strain);
  g.elements[3].channel = static_cast<int>(OutputChannel::actuation);
  g.elements[4].channel = static_cast<int>(OutputChannel::stiffness);
  const std::string text = to_json(g);
  EXPECT_NE(text.find("\"strain\""), std::string::npos);
  EXPECT_NE(text.find("\"actuation\""), std::string::npos);
  EXPECT_NE(text.find("\"stiffness\""), std::string::npos);
  EXPECT_EQ(genome_from_json(text), g);  // loads whatever genome.extra_* say (docs/model.md)
  g.elements[3].channel = kOutputCount;
  EXPECT_THROW(validate(g, GenomeParams{}), GenomeError);
}

TEST(Operators, MutateSignsFlipsAtItsRate) {
  MutationParams m;
  m.sign_rate = 1.0;
  Genome g = random_with(5);
  const Genome before = g;
  Rng rng(1);
  EXPECT_EQ(mutate_signs(g, m, rng), static_cast<int>(g.size()));
  for (std::size_t i = 0; i < g.size(); ++i) {
    EXPECT_EQ(g.elements[i].sign, -before.elements[i].sign);
    EXPECT_EQ(g.elements[i].type, before.elements[i].type);
  }
  EXPECT_NO_THROW(validate(g, GenomeParams{}));
  m.sign_rate = 0.0;
  EXPECT_EQ(mutate_signs(g, m, rng), 0);
  // An intermediate rate flips about that share of the elements.
  m.sign_rate = 0.3;
  int flips = 0, total = 0;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    Genome h = random_with(seed);
    Rng r(seed);
    flips += mutate_signs(h, m, r);
    total += static_cast<int>(h.size());
  }
  EXPECT_NEAR(static_cast<double>(flips) / total, 0.3, 0.03);
}

TEST(Operators, MutateCoordinatesMovesByNormalDistance) {
  MutationParams m;
  m.move_rate = 1.0;
  m.move_sigma = 0.5;
  double sum_abs = 0.0, sum_dx = 0.0, sum_dy = 0.0;
  int moved = 0;
  for (std::uint64_t seed = 0; seed < 300; ++seed) {
    Genome g = random_with(seed);
    const Genome before = g;
    Rng rng(seed);
    EXPECT_EQ(mutate_coordinates(g, m, rng), static_cast<int>(g.size()));
    ASSERT_NO_THROW(validate(g, GenomeParams{}));
    for (std::size_t i = 0; i < g.size(); ++i) {
      EXPECT_EQ(g.elements[i].type, before.elements[i].type);
      EXPECT_EQ(g.elements[i].sign, before.elements[i].sign);
      const double dx = g.elements[i].coords[0] - before.elements[i].coords[0];
      const double dy = g.elements[i].coords[1] - before.elements[i].coords[1];
      sum_abs += std::hypot(dx, dy);
      sum_dx += dx;
      sum_dy += dy;
      ++moved;
    }
  }
  // |N(0, sigma)| has mean sigma*sqrt(2/pi); the direction is isotropic, so the mean move is 0.
  EXPECT_NEAR(sum_abs / moved, 0.5 * std::sqrt(2.0 / std::numbers::pi), 0.01);
  EXPECT_NEAR(sum_dx / moved, 0.0, 0.02);
  EXPECT_NEAR(sum_dy / moved, 0.0, 0.02);

  m.move_sigma = 0.0;
  Genome g = random_with(8);
  const Genome before = g;
  Rng rng(8);
  mutate_coordinates(g, m, rng);
  EXPECT_EQ(g, before);
}

TEST(Operators, DuplicateSeriesInsertsACopyRightAfter) {
  const Genome orig = make({P, G, I, P, M, O, G});
  for (std::size_t start = 0; start < orig.size(); ++start) {
    for (std::size_t len = 1; len <= 4; ++len) {
      Genome g = orig;
      duplicate_series(g, start, len);
      const std::size_t real = std::min(len, orig.size() - start);
      ASSERT_EQ(g.size(), orig.size() + real) << start << "," << len;
      for (std::size_t i = 0; i < start + real; ++i) EXPECT_EQ(g.elements[i], orig.elements[i]);
      for (std::size_t i = 0; i < real; ++i)
        EXPECT_EQ(g.elements[start + real + i], orig.elements[start + i]);
      for (std::size_t i = start + real; i < orig.size(); ++i)
        EXPECT_EQ(g.elements[i + real], orig.elements[i]);
      EXPECT_NO_THROW(validate(g, GenomeParams{}));
    }
  }
  Genome g = orig;
  duplicate_series(g, orig.size(), 3);  // start past the end: no-op
  EXPECT_EQ(g, orig);
  duplicate_series(g, 2, 0);
  EXPECT_EQ(g, orig);
}

TEST(Operators, DeleteSeriesRemovesExactlyTheSeries) {
  const Genome orig = make({P, G, I, P, M, O, G});
  for (std::size_t start = 0; start < orig.size(); ++start) {
    for (std::size_t len = 1; len <= 4; ++len) {
      Genome g = orig;
      delete_series(g, start, len);
      const std::size_t real = std::min(len, orig.size() - start);
      ASSERT_EQ(g.size(), orig.size() - real) << start << "," << len;
      for (std::size_t i = 0; i < start; ++i) EXPECT_EQ(g.elements[i], orig.elements[i]);
      for (std::size_t i = start; i < g.size(); ++i)
        EXPECT_EQ(g.elements[i], orig.elements[i + real]);
      EXPECT_NO_THROW(validate(g, GenomeParams{}));
    }
  }
  Genome g = orig;
  delete_series(g, orig.size(), 2);
  EXPECT_EQ(g, orig);
  delete_series(g, 0, orig.size() + 5);
  EXPECT_TRUE(g.elements.empty());
  EXPECT_NO_THROW(validate(g, GenomeParams{}));
  delete_series(g, 0, 1);  // empty genome: no-op
  EXPECT_TRUE(g.elements.empty());
}

TEST(Operators, MutateKeepsGenomesValidOverManySeedsAndGenerations) {
  MutationParams m;
  m.type_rate = 0.1;
  m.sign_rate = 0.1;
  m.move_rate = 0.5;
  m.move_sigma = 2.0;
  m.duplicate_rate = 0.5;
  m.delete_rate = 0.5;
  m.max_series_length = 6;
  const GenomeParams p;
  for (std::uint64_t seed = 0; seed < 100; ++seed) {
    Genome g = random_with(seed);
    for (int gen = 0; gen < 50; ++gen) {
      Rng rng = Rng::derive(seed, static_cast<std::uint64_t>(gen), 0);
      mutate(g, m, p, rng);
      ASSERT_NO_THROW(validate(g, p)) << "seed " << seed << " generation " << gen;
    }
  }
}

TEST(Operators, MutateNeverGrowsPastMaxElements) {
  MutationParams m;
  m.duplicate_rate = 1.0;
  m.delete_rate = 0.0;
  m.max_series_length = 10;
  GenomeParams p;
  p.max_elements = 45;
  std::size_t largest = 0;
  for (std::uint64_t seed = 0; seed < 50; ++seed) {
    Genome g = random_with(seed, p);
    for (int gen = 0; gen < 100; ++gen) {
      Rng rng = Rng::derive(seed, static_cast<std::uint64_t>(gen));
      mutate(g, m, p, rng);
      ASSERT_LE(g.size(), 45u) << "seed " << seed << " generation " << gen;
      ASSERT_NO_THROW(validate(g, p));
    }
    largest = std::max(largest, g.size());
  }
  EXPECT_GE(largest, 40u);  // duplication did run up towards the cap
}

TEST(Operators, MutateAtRateOneDuplicationGrowsByTheSeriesLength) {
  MutationParams m;
  m.type_rate = m.sign_rate = m.move_rate = 0.0;
  m.duplicate_rate = 1.0;
  m.delete_rate = 0.0;
  m.max_series_length = 3;
  std::set<std::size_t> growths;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    Genome g = random_with(seed);
    const std::size_t before = g.size();
    Rng rng(seed);
    EXPECT_EQ(mutate(g, m, GenomeParams{}, rng), 1);
    growths.insert(g.size() - before);
  }
  EXPECT_EQ(growths, (std::set<std::size_t>{1, 2, 3}));
  m.duplicate_rate = 0.0;
  m.delete_rate = 1.0;
  std::set<std::size_t> shrinks;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    Genome g = random_with(seed);
    const std::size_t before = g.size();
    Rng rng(seed);
    EXPECT_EQ(mutate(g, m, GenomeParams{}, rng), 1);
    shrinks.insert(before - g.size());
  }
  EXPECT_EQ(shrinks, (std::set<std::size_t>{1, 2, 3}));
}

TEST(Operators, MutateIsDeterministic) {
  MutationParams m;
  m.type_rate = m.sign_rate = 0.2;
  m.move_rate = 0.5;
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    Genome a = random_with(seed), b = random_with(seed), c = random_with(seed);
    Rng ra(seed * 7 + 1), rb(seed * 7 + 1), rc(seed * 7 + 2);
    mutate(a, m, GenomeParams{}, ra);
    mutate(b, m, GenomeParams{}, rb);
    mutate(c, m, GenomeParams{}, rc);
    EXPECT_TRUE(bit_equal(a, b));
    EXPECT_EQ(ra, rb);
    EXPECT_FALSE(a == c);
  }
}

TEST(Operators, CrossoverOfIdenticalParentsIsTheSameGenome) {
  for (std::uint64_t seed = 0; seed < 100; ++seed) {
    const Genome a = random_with(seed);
    for (int points : {1, 2, 3, 7}) {
      Rng rng(seed * 31 + static_cast<std::uint64_t>(points));
      EXPECT_TRUE(bit_equal(crossover(a, a, points, rng), a))
          << "seed " << seed << " points " << points;
    }
  }
}

TEST(Operators, CrossoverOfDifferentLengthsIsBuiltFromParentSegments) {
  GenomeParams pshort;
  pshort.initial_units = 3;
  GenomeParams plong;
  plong.initial_units = 25;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    const Genome a = random_with(seed, seed % 2 ? pshort : plong);
    const Genome b = random_with(seed + 10000, seed % 2 ? plong : pshort);
    const int points = 1 + static_cast<int>(seed % 4);
    Rng rng(seed);
    Rng replay = rng;
    const Genome child = crossover(a, b, points, rng);
    ASSERT_NO_THROW(validate(child, GenomeParams{})) << "seed " << seed;
    ASSERT_TRUE(child.size() == a.size() || child.size() == b.size());
    // Position-preserving: every element comes from the same index of one parent, and the parent
    // switches at most `points` times.
    int switches = 0, from = -1;
    for (std::size_t i = 0; i < child.size(); ++i) {
      const bool in_a = i < a.size() && child.elements[i] == a.elements[i];
      const bool in_b = i < b.size() && child.elements[i] == b.elements[i];
      ASSERT_TRUE(in_a || in_b) << "seed " << seed << " index " << i;
      const int now = in_a ? 0 : 1;
      if (from >= 0 && now != from) ++switches;
      from = now;
    }
    EXPECT_LE(switches, points);
    // The documented construction: sorted cut points in [0, min(|a|,|b|)], segments alternate from
    // a.
    const std::size_t shortest = std::min(a.size(), b.size());
    std::vector<std::size_t> cuts;
    for (int k = 0; k < points; ++k) cuts.push_back(replay.below(shortest + 1));
    std::sort(cuts.begin(), cuts.end());
    Genome expected;
    expected.dimensions = 2;
    std::size_t pos = 0;
    int cur = 0;
    for (std::size_t cut : cuts) {
      const Genome& src = cur ? b : a;
      for (std::size_t i = pos; i < cut; ++i) expected.elements.push_back(src.elements[i]);
      pos = cut;
      cur ^= 1;
    }
    const Genome& tail = cur ? b : a;
    for (std::size_t i = pos; i < tail.size(); ++i) expected.elements.push_back(tail.elements[i]);
    EXPECT_TRUE(bit_equal(child, expected)) << "seed " << seed;
  }
}

TEST(Operators, CrossoverWithAnEmptyParentIsValid) {
  const Genome a = random_with(1);
  const Genome empty;
  for (int points : {1, 2, 3}) {
    Rng rng(static_cast<std::uint64_t>(points));
    const Genome c1 = crossover(a, empty, points, rng);
    const Genome c2 = crossover(empty, a, points, rng);
    EXPECT_NO_THROW(validate(c1, GenomeParams{}));
    EXPECT_NO_THROW(validate(c2, GenomeParams{}));
    EXPECT_TRUE(c1 == a || c1.elements.empty());
    EXPECT_TRUE(c2 == a || c2.elements.empty());
  }
}

TEST(Operators, CrossoverOfDifferentDimensionsIsRejectedOrValid) {
  // Parents from different affinity spaces cannot be recombined: the result must not be a genome
  // whose elements disagree with its own `dimensions`.
  GenomeParams p3;
  p3.dimensions = 3;
  const Genome a = random_with(1), b = random_with(2, p3);
  Rng rng(5);
  bool threw = false;
  Genome child;
  try {
    child = crossover(a, b, 2, rng);
  } catch (const Error&) {
    threw = true;
  }
  if (!threw) {
    EXPECT_NO_THROW(validate(child, GenomeParams{}))
        << "crossover silently mixed 2-D and 3-D elements";
  }
}

// ---------------------------------------------------------------------------------------------------
// JSON

TEST(Json, RoundTripIsBitExactIncludingAwkwardDoubles) {
  Genome g = make({P, G, M, I, O, P, G});
  g.elements[3].channel = 2;
  g.elements[4].channel = 5;
  g.elements[1].sign = -1;
  const double awkward[] = {0.1,
                            1e-300,
                            -0.0,
                            0.0,
                            std::numeric_limits<double>::denorm_min(),
                            DBL_MIN,
                            DBL_MAX,
                            -DBL_MAX,
                            1.0 / 3.0,
                            std::numbers::pi,
                            9007199254740993.0,  // 2^53 + 1 rounds to 2^53
                            123456789.123456789,
                            -2.5e-8,
                            std::nextafter(1.0, 2.0)};
  std::size_t k = 0;
  for (auto& e : g.elements)
    for (double& x : e.coords) x = awkward[k++ % std::size(awkward)];
  for (int indent : {-1, 0, 2}) {
    const std::string text = to_json(g, indent);
    const Genome back = genome_from_json(text);
    EXPECT_TRUE(bit_equal(back, g)) << text;
    EXPECT_EQ(to_json(back, indent), text);
    EXPECT_EQ(genome_hash(back), genome_hash(g));
  }
  // -0.0 keeps its sign
  EXPECT_TRUE(std::signbit(genome_from_json(to_json(g)).elements[1].coords[0]));
}

TEST(Json, RoundTripOfRandomAndMutatedGenomes) {
  MutationParams m;
  m.move_rate = 1.0;
  for (std::uint64_t seed = 0; seed < 30; ++seed) {
    Genome g = random_with(seed);
    Rng rng(seed);
    mutate(g, m, GenomeParams{}, rng);
    EXPECT_TRUE(bit_equal(genome_from_json(to_json(g)), g));
  }
  GenomeParams p;
  p.dimensions = 5;
  const Genome g5 = random_with(3, p);
  EXPECT_TRUE(bit_equal(genome_from_json(to_json(g5), p), g5));
}

TEST(Json, FormatAndVersionFieldsAndNamedChannels) {
  Genome g = make({I, O, P});
  g.elements[0].channel = 1;
  g.elements[1].channel = 4;
  const std::string text = to_json(g);
  EXPECT_NE(text.find("\"format\":\"animat.genome\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"version\":1"), std::string::npos) << text;
  EXPECT_NE(text.find("\"dimensions\":2"), std::string::npos) << text;
  EXPECT_NE(text.find("\"channel\":\"maternal0\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"channel\":\"frequency\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"type\":\"promoter\""), std::string::npos) << text;
  EXPECT_EQ(kGenomeFormatVersion, 1);
}

TEST(Json, EmptyGenomeRoundTrips) {
  const Genome g;
  EXPECT_EQ(genome_from_json(to_json(g)), g);
}

TEST(Json, SaveAndLoadFile) {
  const fs::path path = temp_path("roundtrip.json");
  const Genome g = random_with(77);
  save_genome(g, path);
  EXPECT_TRUE(bit_equal(load_genome(path), g));
  fs::remove(path);
  const std::string m = message_of([&] { (void)load_genome(path); });
  EXPECT_NE(m.find(path.string()), std::string::npos) << m;
  EXPECT_THROW((void)load_genome(path), IoError);
  EXPECT_THROW(save_genome(g, fs::path("/nonexistent_dir_animat/x.json")), IoError);
}

TEST(Json, GenomeHashEqualGenomesEqualHashes) {
  const Genome a = random_with(4);
  Genome b = a;
  EXPECT_EQ(genome_hash(a), genome_hash(b));
  b.elements[3].coords[0] = std::nextafter(b.elements[3].coords[0], 100.0);
  EXPECT_NE(genome_hash(a), genome_hash(b));
  Genome c = a;
  c.elements[0].sign = -c.elements[0].sign;
  EXPECT_NE(genome_hash(a), genome_hash(c));
  // Documented: "equal genomes, equal hashes". 0.0 == -0.0, so these genomes compare equal.
  Genome z1 = make({P, G}), z2 = make({P, G});
  z1.elements[0].coords[0] = 0.0;
  z2.elements[0].coords[0] = -0.0;
  ASSERT_TRUE(z1 == z2);
  EXPECT_EQ(genome_hash(z1), genome_hash(z2))
      << "equal genomes (0.0 vs -0.0 coordinate) hash differently";
}

// --- Bad JSON: every case is a GenomeError whose message names the file and the problem.

struct BadGenomeCase {
  const char* file;
  std::vector<std::string> expect;  // substrings of the message
};

void PrintTo(const BadGenomeCase& c, std::ostream* os) { *os << c.file; }

class BadGenomeJson : public ::testing::TestWithParam<BadGenomeCase> {};

TEST_P(BadGenomeJson, IsAGenomeErrorNamingFileAndProblem) {
  const auto& c = GetParam();
  const fs::path path = bad_input(c.file);
  ASSERT_TRUE(fs::exists(path)) << path;
  std::string msg;
  bool genome_error = false;
  try {
    (void)load_genome(path);
    msg = "<accepted>";
  } catch (const GenomeError& e) {
    genome_error = true;
    msg = e.what();
  } catch (const std::exception& e) {
    msg = std::string("<not a GenomeError> ") + e.what();
  }
  EXPECT_TRUE(genome_error) << c.file << ": " << msg;
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
  for (const auto& s : c.expect)
    EXPECT_NE(msg.find(s), std::string::npos) << "expected '" << s << "' in: " << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadGenomeJson,
    ::testing::Values(
        BadGenomeCase{"genome_truncated.json", {"not valid JSON"}},
        BadGenomeCase{"genome_binary.json", {"not valid JSON"}},
        BadGenomeCase{"genome_empty_file.json", {"not valid JSON"}},
        BadGenomeCase{"genome_nan_literal.json", {"not valid JSON"}},
        BadGenomeCase{"genome_infinity_literal.json", {"not valid JSON"}},
        BadGenomeCase{"genome_overflow.json", {"1e999"}},
        BadGenomeCase{"genome_unknown_type.json", {"element 1", "unknown type \"enhancer\""}},
        BadGenomeCase{"genome_input_channel_out_of_range.json",
                      {"element 0", "channel \"maternal7\"", "input"}},
        BadGenomeCase{"genome_output_channel_number.json", {"element 0", "channel 6", "output"}},
        BadGenomeCase{"genome_missing_coords.json", {"element 0", "missing key \"coords\""}},
        BadGenomeCase{"genome_missing_elements.json", {"missing key \"elements\""}},
        BadGenomeCase{"genome_wrong_version.json", {"\"version\" 2", "version 1"}},
        BadGenomeCase{"genome_version_wraps_to_1.json", {"\"version\" 4294967297"}},
        BadGenomeCase{"genome_wrong_format.json", {"\"animat.chromosome\"", "\"animat.genome\""}},
        BadGenomeCase{"genome_sign_zero.json", {"element 0", "sign is 0"}},
        BadGenomeCase{"genome_sign_wraps_to_minus_1.json",
                      {"element 0", "sign is 18446744073709551615"}},
        BadGenomeCase{"genome_coords_wrong_length.json",
                      {"element 0", "coords must be an array of 2 numbers"}},
        BadGenomeCase{"genome_dimensions_zero.json", {"\"dimensions\" is 0"}},
        BadGenomeCase{"genome_channel_on_promoter.json", {"element 0", "promoter has no channel"}},
        BadGenomeCase{"genome_not_an_object.json", {"expected a JSON object"}}),
    [](const ::testing::TestParamInfo<BadGenomeCase>& info) {
      std::string n = info.param.file;
      n = n.substr(0, n.find('.'));
      for (char& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

TEST(JsonBad, NonFiniteCoordinatesNamedFromString) {
  // A string source: the message names it.
  const std::string text =
      R"({"format":"animat.genome","version":1,"dimensions":2,"elements":[{"type":"promoter","sign":1,"coords":[1,2]},)"
      R"({"type":"input","sign":1,"channel":"bias","coords":[-1e400,0]}]})";
  const std::string m =
      message_of([&] { (void)genome_from_json(text, GenomeParams{}, "parents.json"); });
  EXPECT_NE(m.find("parents.json"), std::string::npos) << m;
  EXPECT_NE(m.find("1e400"), std::string::npos) << m;
  EXPECT_THROW((void)genome_from_json(text, GenomeParams{}, "parents.json"), GenomeError);
}

TEST(JsonBad, TooManyElementsForMaxElements) {
  // 10^7 elements against the default cap of 10,000: rejected by size, naming both numbers.
  std::string text = R"({"format":"animat.genome","version":1,"dimensions":2,"elements":[)";
  const std::size_t n = 10'000'000;
  text.reserve(text.size() + 2 * n + 4);
  for (std::size_t i = 0; i < n; ++i) text += i ? ",0" : "0";
  text += "]}";
  const std::string m =
      message_of([&] { (void)genome_from_json(text, GenomeParams{}, "huge.json"); });
  EXPECT_NE(m.find("huge.json: 10000000 elements exceed genome.max_elements = 10000"),
            std::string::npos)
      << m.substr(0, 300);

  // Valid elements, one more than a small cap.
  GenomeParams p;
  p.max_elements = 10;
  Genome g = make({P, G, P, G, P, G, P, G, P, G, P});
  const std::string m2 = message_of([&] { (void)genome_from_json(to_json(g), p, "g.json"); });
  EXPECT_NE(m2.find("11 elements exceed genome.max_elements = 10"), std::string::npos) << m2;
  g.elements.pop_back();
  EXPECT_NO_THROW((void)genome_from_json(to_json(g), p, "g.json"));
}

TEST(JsonBad, WrongJsonTypesAreGenomeErrors) {
  const char* cases[] = {
      R"({"format":"animat.genome","version":1,"dimensions":2,"elements":{}})",
      R"({"format":"animat.genome","version":1,"dimensions":2,"elements":[5]})",
      R"({"format":"animat.genome","version":1,"dimensions":2,"elements":[{"type":3,"sign":1,"coords":[0,0]}]})",
      R"({"format":"animat.genome","version":1,"dimensions":2,"elements":[{"type":"promoter","sign":"+","coords":[0,0]}]})",
      R"({"format":"animat.genome","version":1,"dimensions":2,"elements":[{"type":"promoter","sign":1,"coords":["a",0]}]})",
      R"({"format":"animat.genome","version":1,"dimensions":2,"elements":[{"type":"promoter","sign":1.0,"coords":[0,0]}]})",
      R"({"format":"animat.genome","version":1.0,"dimensions":2,"elements":[]})",
      R"({"format":"animat.genome","version":1,"dimensions":"2","elements":[]})",
      R"({"format":"animat.genome","version":1,"dimensions":17,"elements":[]})",
      R"({"version":1,"dimensions":2,"elements":[]})",
      R"({"format":"animat.genome","version":1,"dimensions":2,"elements":[{"type":"output","sign":1,"coords":[0,0]}]})",
  };
  for (const char* text : cases) {
    bool genome_error = false;
    std::string msg;
    try {
      (void)genome_from_json(text, GenomeParams{}, "case.json");
    } catch (const GenomeError& e) {
      genome_error = true;
      msg = e.what();
    } catch (const std::exception& e) {
      msg = e.what();
    }
    EXPECT_TRUE(genome_error) << text << " -> " << msg;
    EXPECT_EQ(msg.rfind("case.json", 0), 0u) << msg;
  }
}
