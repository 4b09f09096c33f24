// The locomotion classifier of the engine (locomotion.hpp), for tests against animat.locomotion.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "animat/locomotion.hpp"
#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace animat::py {
namespace {

using Contig = FloatArray;

/// as_float_array(obj) with `ndim` dimensions, else a ValueError naming `name`.
Contig float_array(nb::handle obj, std::size_t ndim, const char* name) {
  const Contig a = as_float_array(obj);
  if (a.ndim() != ndim)
    throw std::invalid_argument(std::string("_classify_motion: ") + name + " must have " +
                                std::to_string(ndim) + " dimensions, got " +
                                std::to_string(a.ndim()));
  return a;
}

nb::dict wave_dict(const WaveMeasure& w) {
  nb::dict d;
  d["gradient"] = nb::make_tuple(w.gradient[0], w.gradient[1]);
  d["fit"] = w.fit;
  d["lag"] = w.lag;
  d["travelling_index"] = w.travelling_index;
  d["coherence"] = w.coherence;
  d["angle"] = w.angle;
  d["is_wave"] = w.is_wave;
  d["p_value"] = w.p_value;
  return d;
}

nb::dict stroke_dict(const ProtrusionStroke& st) {
  nb::dict d;
  nb::list protrusions, pairs;
  for (const auto& g : st.protrusions) protrusions.append(nb::tuple(nb::cast(g)));
  for (const auto& [a, b] : st.pairs) pairs.append(nb::make_tuple(a, b));
  d["protrusions"] = nb::tuple(protrusions);
  d["at_rest"] = nb::tuple(nb::cast(st.at_rest));
  d["scores"] = nb::cast(st.scores);
  d["areas"] = nb::cast(st.areas);
  d["pairs"] = nb::tuple(pairs);
  d["pair_scores"] = nb::cast(st.pair_scores);
  d["pair"] = st.pair >= 0
                  ? nb::object(nb::make_tuple(st.pairs[st.pair].first, st.pairs[st.pair].second))
                  : nb::object(nb::tuple());
  d["score"] = st.score;
  d["area"] = st.area;
  d["strokes"] = st.strokes();
  return d;
}

nb::dict classify(nb::handle positions, nb::handle times, nb::handle springs, double omega,
                  double cycles, bool bending, std::optional<double> swim_start,
                  std::optional<std::vector<int>> outline, nb::handle rest_positions) {
  const Contig p = float_array(positions, 3, "positions");
  if (p.shape(2) != 2)
    throw std::invalid_argument("_classify_motion: positions must be (frames, n, 2)");
  const Contig t = float_array(times, 1, "times");
  MotionFrames frames;
  frames.cells = static_cast<int>(p.shape(1));
  frames.xy.assign(p.data(), p.data() + p.size());
  frames.times.assign(t.data(), t.data() + t.size());
  if (swim_start) frames.swim_start = *swim_start;
  if (frames.frame_count() != static_cast<int>(p.shape(0)))
    throw std::invalid_argument("_classify_motion: " + std::to_string(t.size()) + " times for " +
                                std::to_string(p.shape(0)) + " frames");
  const Contig s = float_array(
      nb::module_::import_("numpy").attr("reshape")(springs, nb::make_tuple(-1, 2)), 2, "springs");
  IndexPairs pairs(static_cast<Eigen::Index>(s.shape(0)), 2);
  for (std::size_t k = 0; k < s.size(); ++k) pairs.data()[k] = static_cast<int>(s.data()[k]);
  StrokeBody stroke;
  Points rest;
  if (outline) stroke.outline = *outline;
  if (!rest_positions.is_none()) {
    const Contig r = float_array(rest_positions, 2, "rest_positions");
    if (r.shape(1) != 2)
      throw std::invalid_argument("_classify_motion: rest_positions must be (n, 2)");
    rest = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(
        r.data(), static_cast<Eigen::Index>(r.shape(0)), 2);
    stroke.rest_positions = &rest;
  }
  LocomotionMode m;
  {
    nb::gil_scoped_release release;
    m = classify_motion(frames, pairs, omega, cycles, bending, outline ? &stroke : nullptr);
  }
  nb::dict d;
  d["mode"] = locomotion_name(m.mode);
  nb::list mixed;
  for (Locomotion x : m.mixed) mixed.append(locomotion_name(x));
  d["mixed"] = nb::tuple(mixed);
  d["deformation"] = m.deformation;
  d["coherence"] = m.coherence;
  d["concentration"] = m.concentration;
  d["travelling_index"] = m.travelling_index;
  d["wave"] = m.has_wave ? nb::object(wave_dict(m.wave)) : nb::none();
  d["bend"] = m.has_bend ? nb::object(wave_dict(m.bend)) : nb::none();
  d["omega"] = m.omega;
  d["cycles"] = m.cycles;
  d["frames"] = m.frames;
  d["direction"] = nb::make_tuple(m.direction[0], m.direction[1]);
  d["speed"] = m.speed;
  nb::list top, phases, amplitudes;
  for (int c : m.top_cells) top.append(c);
  for (double v : m.phases) phases.append(v);
  for (double v : m.amplitudes) amplitudes.append(v);
  d["top_cells"] = top;
  d["phases"] = phases;
  d["amplitudes"] = amplitudes;
  d["contrast"] = m.contrast;
  d["groups"] = m.groups;
  d["stroke"] = m.has_stroke ? nb::object(stroke_dict(m.stroke)) : nb::none();
  return d;
}

}  // namespace

void bind_locomotion(nb::module_& m) {
  m.def("_classify_motion", &classify, "positions"_a, "times"_a, "springs"_a, "omega"_a,
        "cycles"_a = 4.0, "bending"_a = false, "swim_start"_a = nb::none(),
        "outline"_a = nb::none(), "rest_positions"_a = nb::none(),
        "The engine's locomotion classifier (animat.locomotion.classify_motion; bending: also the "
        "bending wave; swim_start: the swim's first time when the frames are only its end; "
        "outline, rest_positions: the stroke path's body): a dict of the LocomotionMode's "
        "numbers, mode and mixed as names of animat.locomotion.MODES.");
  m.def(
      "_dominant_frequency",
      [](nb::handle amplitude, nb::handle frequency) {
        const Contig a = float_array(amplitude, 1, "amplitude");
        const Contig f = float_array(frequency, 1, "frequency");
        return dominant_frequency(
            Eigen::Map<const Vector>(a.data(), static_cast<Eigen::Index>(a.size())),
            Eigen::Map<const Vector>(f.data(), static_cast<Eigen::Index>(f.size())));
      },
      "amplitude"_a, "frequency"_a,
      "The engine's dominant actuation frequency of a body (2 pi / animat.Trajectory.period(); 0 "
      "when no cell oscillates).");
  m.def("_locomotion_window_start", &window_start_step, "steps"_a, "dt"_a, "omega"_a,
        "cycles"_a = 4.0,
        "The first control step whose frame the engine's locomotion classifier can need.");
}

}  // namespace animat::py
