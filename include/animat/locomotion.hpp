#pragma once
// The locomotion mode of a swim (undulation, synchronous contraction, protrusions, tail, other,
// none), classified from frames of the swim as animat.locomotion.classify_motion classifies them,
// so that the engine can classify the evaluation's own swim instead of swimming it again.
//
// Frames. animat.replay(thing, config, every=1) records frame 0 (the start state, t = 0) and one
// frame after every control step (t = k·dt), steps + 1 frames in all. The classifier reads only its
// window: the last k = min(cycles, floor(second half / period)) whole periods 2π/ω of the record
// (at least the last 8 frames), so it never reaches before step steps / 2. A recorder therefore
// needs only the frames of steps window_start_step(steps, dt, ω, cycles) .. steps, about
// k·2π/(ω·dt) + 2 of them, known before the swim once ω is (dominant_frequency() of the body).
// With the defaults (4000 steps of dt = 1/60, cycles = 4, f in [0.5, 6]): 253 frames at f = 6,
// 1509 at f = 0.5 (where the second half holds only 2 whole periods), never more than 2002:
// preallocate steps / 2 + 2 frames of cells × 2 doubles. Pass them with MotionFrames::swim_start
// = 0 (the time of frame 0) and the classification is the full record's, bit for bit.
//
// The stroke path. Given the body's outline (and its rest positions), the classifier also measures
// the paper's protrusion stroke (animat.protrusion.stroke_motion: a symmetric pair of protrusions
// extended while moving backwards) and decides "protrusions" by it first, and counts a bending
// wave as a wave: animat.locomotion.classify_locomotion's default path, which
// classify_body_motion() takes. Without an outline it is classify_motion without one (the earlier
// rules), with the bending wave optional (`bending`).
#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "animat/types.hpp"

namespace animat {

struct Body;

/// The modes, in the order of animat.locomotion.MODES.
enum class Locomotion : int {
  undulation = 0,
  synchronous_contraction,
  protrusions,
  tail,
  other,
  none,
};
/// The name animat.locomotion.MODES gives a mode ("synchronous contraction", ...).
[[nodiscard]] const char* locomotion_name(Locomotion mode);

/// Node positions of a swim: frame-major, `cells` × 2 values (x, y) per frame, one time per frame
/// (uniformly sampled, increasing).
struct MotionFrames {
  int cells = 0;
  std::vector<double> xy;
  std::vector<double> times;
  /// The time of the swim's first frame when the frames are only its end (a recorder that kept the
  /// steps from window_start_step() on): the window is chosen from the whole swim's duration, so it
  /// is the window of the full record. NaN: times.front() (the frames are the whole swim).
  double swim_start = std::numeric_limits<double>::quiet_NaN();
  [[nodiscard]] int frame_count() const { return static_cast<int>(times.size()); }
};

/// The circular-linear phase fit of a contraction field (animat.locomotion.WaveFit).
struct WaveMeasure {
  std::array<double, 2> gradient{0.0, 0.0};  ///< phase gradient, rad per length unit (body frame)
  double fit = 0.0;                          ///< weighted resultant after removing the gradient
  double lag = 0.0;                          ///< total phase lag across the moving cells (rad)
  double travelling_index = 0.0;
  double coherence = 0.0;
  double angle = 0.0;    ///< degrees between the wave's travel and the motion; NaN when undefined
  bool is_wave = false;  ///< the wave criterion holds
  /// Permutation p-value of the bending wave, computed only when every other bending criterion
  /// holds and only while it can still reach BEND_P (the shuffles cost most of the classifier): NaN
  /// when not tested or when 10 shuffles already fit as well (p > 0.01); NaN for the contraction
  /// wave.
  double p_value = 0.0;
};

/// The stroke of a swim's protrusions (animat.protrusion.ProtrusionStroke).
struct ProtrusionStroke {
  std::vector<std::vector<int>> protrusions;  ///< cell groups (ascending), at rest ones first
  std::vector<bool> at_rest;                  ///< per protrusion: some cell protrudes at rest
  std::vector<double> scores;                 ///< weighted rowing correlation (NaN: no motion)
  std::vector<double> areas;                  ///< signed loop area, spacings²
  std::vector<std::pair<int, int>> pairs;     ///< symmetric pairs (indices into protrusions)
  std::vector<double> pair_scores;            ///< the smaller score of each pair
  int pair = -1;                              ///< the best eligible pair (index into pairs), or -1
  double score = std::numeric_limits<double>::quiet_NaN();  ///< its pair score
  double area = std::numeric_limits<double>::quiet_NaN();   ///< its smaller area
  /// The best pair rows as the paper describes (score >= 0.4, area >= 0.1: STROKE_SCORE,
  /// STROKE_AREA).
  [[nodiscard]] bool strokes() const;
};

/// The body that the stroke path reads: the outer skin loop and, optionally, the rest positions.
struct StrokeBody {
  std::span<const int> outline;            ///< Body::skin_loops[0]
  const Points* rest_positions = nullptr;  ///< Body::positions (nullptr: frames only)
};

/// The classifier's result: the numbers of animat.locomotion.LocomotionMode.
struct LocomotionMode {
  Locomotion mode = Locomotion::none;
  std::vector<Locomotion> mixed;  ///< other modes whose criterion also holds
  double deformation = 0.0;
  double coherence = 0.0;
  double concentration = 0.0;
  double travelling_index = 0.0;
  bool has_wave = false;  ///< `wave` was measured (false for mode none)
  WaveMeasure wave;
  bool has_bend = false;  ///< `bend` was measured (bending on and a deforming body)
  WaveMeasure bend;
  double omega = 0.0;
  double cycles = 0.0;                        ///< periods in the window
  int frames = 0;                             ///< frames in the window (the last `frames` frames)
  std::array<double, 2> direction{1.0, 0.0};  ///< direction of motion, body frame
  double speed = 0.0;
  std::vector<int> top_cells;              ///< the most mobile 20 % of the cells, ascending
  std::vector<double> phases, amplitudes;  ///< of each cell's contraction
  double contrast = 0.0;
  int groups = 0;
  bool has_stroke = false;  ///< `stroke` was measured (an outline of >= 3 cells, a deforming body)
  ProtrusionStroke stroke;
};

/// Classifies a swim as animat.locomotion.classify_motion(positions, times, springs=springs,
/// omega=omega, cycles=cycles, bending=bending, outline=..., rest_positions=...) does, with the
/// stroke rule when `stroke` is given (its outline and rest positions). Deterministic: the bending
/// wave's shuffles use Rng(kBendSeed), not numpy's generator, so its p-value differs from Python's
/// by the sampling error of 999 shuffles. Throws std::invalid_argument for fewer than 8 frames,
/// sizes that do not match, or a spring or outline entry naming no cell.
[[nodiscard]] LocomotionMode classify_motion(const MotionFrames& frames, const IndexPairs& springs,
                                             double omega, double cycles = 4.0,
                                             bool bending = false,
                                             const StrokeBody* stroke = nullptr);

/// The default path of animat.locomotion.classify_locomotion(genome, config) on frames of `body`'s
/// swim: its springs, its dominant frequency, the stroke rule on its outline (and on
/// `rest_positions`, the start of the swim; nullptr: body.positions) with the bending wave; a body
/// without skin loops has no outline: the earlier rules.
[[nodiscard]] LocomotionMode classify_body_motion(const MotionFrames& frames, const Body& body,
                                                  double cycles = 4.0,
                                                  const Points* rest_positions = nullptr);

/// Seed of the bending wave's shuffles (animat.locomotion.BEND_SEED's role).
inline constexpr std::uint64_t kBendSeed = 0;

/// The dominant actuation frequency of a body (rad per time unit), as animat.Trajectory.period()
/// picks it: the amplitude-weighted median of the frequencies of the cells with a > 0 and f > 0;
/// 0 when no cell oscillates.
[[nodiscard]] double dominant_frequency(const Vector& amplitude, const Vector& frequency);

/// The first control step whose frame (t = step·dt) the classifier's window can need for a swim of
/// `steps` control steps at angular frequency `omega` with `cycles` periods: record the frames of
/// steps window_start_step(...) .. steps.
[[nodiscard]] int window_start_step(int steps, double dt, double omega, double cycles = 4.0);

}  // namespace animat
