// The measures' table (search.hpp): what MAP-Elites' descriptors and NSGA-II's criteria read of
// an evaluation's Fitness.
#include <fmt/format.h>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/search.hpp"

namespace animat {

namespace {

// Descriptor ranges (the paper's settings; animat.qd.DESCRIPTORS takes them from here): integer
// descriptors one wider than their values, so that hi - lo bins give each value its own bin.
constexpr Measure kMeasures[] = {
    {"fitness", "the objective's value (evaluation.objective)", 0.0, 50.0, true,
     [](const Fitness& f) { return f.fitness; }},
    {"cells", "number of cells of the developed embryo", 1.0, 65.0, true,
     [](const Fitness& f) { return static_cast<double>(f.cell_count); }},
    {"actuation_work", "net mechanical work of actuation on the springs", 0.0, 0.0, false,
     [](const Fitness& f) { return f.actuation_work; }},
    {"actuation_work_positive", "positive actuation work: what the actuators spend", 0.0, 0.0,
     false, [](const Fitness& f) { return f.actuation_work_positive; }},
    {"actuation_work_absolute", "absolute actuation work", 0.0, 0.0, false,
     [](const Fitness& f) { return f.actuation_work_absolute; }},
    {"max_speed", "largest cell speed seen in the swim", 0.0, 0.0, true,
     [](const Fitness& f) { return f.max_speed; }},
    {"elongation", "elongation of the body at rest (animat.shape)", 1.0, 4.0, true,
     [](const Fitness& f) { return f.elongation; }},
    {"protrusions", "number of protrusions: parts sticking out of the body's core", 0.0, 8.0, true,
     [](const Fitness& f) { return static_cast<double>(f.protrusions); }},
    {"symmetric_pair", "1 when two protrusions mirror each other about a principal axis, else 0",
     0.0, 2.0, true, [](const Fitness& f) { return static_cast<double>(f.symmetric_pair); }},
    {"concavity", "1 - outline area / convex hull area of the body at rest", 0.0, 0.5, true,
     [](const Fitness& f) { return f.concavity; }},
    {"frequency", "median oscillator frequency of the cells (rad per time unit)", 0.5, 6.0, true,
     [](const Fitness& f) { return f.frequency; }},
    {"locomotion",
     "locomotion mode: the index in animat.locomotion.MODES (0 undulation ... 5 none), classified "
     "during the swim",
     0.0, 6.0, true, [](const Fitness& f) { return static_cast<double>(f.locomotion); }},
};

}  // namespace

std::span<const Measure> measures() { return kMeasures; }

const Measure& find_measure(std::string_view name, const Config& config, std::string_view key) {
  if (name == config.evaluation.objective) return kMeasures[0];
  for (const Measure& m : kMeasures)
    if (name == m.name) return m;
  std::string names;
  for (const Measure& m : kMeasures) names += (names.empty() ? "" : ", ") + std::string(m.name);
  throw ConfigError(fmt::format(
      "{}: no measure \"{}\" in animat_evolve; its measures are {} (and \"{}\", the "
      "evaluation.objective, as \"fitness\"); the other criteria of animat.moo.CRITERIA run in "
      "Python (`animat evolve`)",
      key, name, names, config.evaluation.objective));
}

}  // namespace animat
