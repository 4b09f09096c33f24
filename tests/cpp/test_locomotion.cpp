// The engine's locomotion classifier (locomotion.hpp) on swims whose mode is known by construction.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "animat/locomotion.hpp"

namespace animat {
namespace {

constexpr double kOmega = 3.0;
constexpr double kDt = 0.05;

/// A ladder of 2 × 10 cells one unit apart (top row y = 1, bottom y = 0), with its horizontal,
/// vertical and one diagonal spring per square. Cell 2i is (i, 0), 2i + 1 is (i, 1).
IndexPairs ladder_springs() {
  std::vector<std::array<int, 2>> s;
  for (int i = 0; i < 10; ++i) {
    s.push_back({2 * i, 2 * i + 1});
    if (i + 1 < 10) {
      s.push_back({2 * i, 2 * i + 2});
      s.push_back({2 * i + 1, 2 * i + 3});
      s.push_back({2 * i, 2 * i + 3});
    }
  }
  IndexPairs p(static_cast<Eigen::Index>(s.size()), 2);
  for (std::size_t k = 0; k < s.size(); ++k)
    p.row(static_cast<Eigen::Index>(k)) << s[k][0], s[k][1];
  return p;
}

/// 600 frames of the ladder, cell c at `offset(c, t)` from its rest place, the whole body turned by
/// 0.2 t and carried along at speed 0.3: rigid motions the classifier must ignore.
MotionFrames ladder_swim(const std::function<std::array<double, 2>(int, double)>& offset) {
  MotionFrames f;
  f.cells = 20;
  for (int k = 0; k < 600; ++k) {
    const double t = k * kDt;
    f.times.push_back(t);
    const double c = std::cos(0.2 * t), s = std::sin(0.2 * t);
    for (int cell = 0; cell < 20; ++cell) {
      const auto d = offset(cell, t);
      const double x = cell / 2 + d[0], y = cell % 2 + d[1];
      f.xy.push_back(c * x - s * y + 0.3 * t);
      f.xy.push_back(s * x + c * y);
    }
  }
  return f;
}

TEST(Locomotion, ATravellingWaveAlongTheBodyIsUndulation) {
  const MotionFrames f = ladder_swim([](int cell, double t) -> std::array<double, 2> {
    return {0.2 * std::sin(kOmega * t - 0.6 * (cell / 2)), 0.0};
  });
  const LocomotionMode m = classify_motion(f, ladder_springs(), kOmega);
  EXPECT_EQ(m.mode, Locomotion::undulation) << locomotion_name(m.mode);
  EXPECT_GT(m.wave.fit, 0.95);
  EXPECT_GT(m.wave.lag, std::numbers::pi / 2);
  EXPECT_GT(m.travelling_index, 0.15);
  EXPECT_TRUE(m.wave.is_wave);
  // The window: the last 4 whole periods, 4 · 2π/3 / 0.05 = 167.6 frame intervals.
  EXPECT_DOUBLE_EQ(m.cycles, 4.0);
  EXPECT_EQ(m.frames, 168);
}

TEST(Locomotion, UniformBreathingIsSynchronousContraction) {
  const MotionFrames f = ladder_swim([](int cell, double t) -> std::array<double, 2> {
    const double r = 0.1 * std::sin(kOmega * t);  // every length scales by 1 + r
    return {r * (cell / 2 - 4.5), r * (cell % 2 - 0.5)};
  });
  const LocomotionMode m = classify_motion(f, ladder_springs(), kOmega);
  EXPECT_EQ(m.mode, Locomotion::synchronous_contraction) << locomotion_name(m.mode);
  EXPECT_NEAR(m.coherence, 1.0, 1e-9);
  EXPECT_LT(m.travelling_index, 1e-6);
  EXPECT_FALSE(m.wave.is_wave);
}

TEST(Locomotion, ARigidBodyIsNone) {
  const MotionFrames f =
      ladder_swim([](int, double) -> std::array<double, 2> { return {0.0, 0.0}; });
  const LocomotionMode m = classify_motion(f, ladder_springs(), kOmega, 4.0, true);
  EXPECT_EQ(m.mode, Locomotion::none);
  EXPECT_LT(m.deformation, 1e-9);
  EXPECT_FALSE(m.has_wave);
  // The centre's straight path over the window, over its duration: the rest centre (4.5, 0.5)
  // turned by 0.2 t and carried by 0.3 t, from frame 432 to 599.
  const auto centre = [](double t) {
    return std::array<double, 2>{std::cos(0.2 * t) * 4.5 - std::sin(0.2 * t) * 0.5 + 0.3 * t,
                                 std::sin(0.2 * t) * 4.5 + std::cos(0.2 * t) * 0.5};
  };
  const double t0 = 432 * kDt, t1 = 599 * kDt;
  const auto a = centre(t0), b = centre(t1);
  EXPECT_NEAR(m.speed, std::hypot(b[0] - a[0], b[1] - a[1]) / (t1 - t0), 1e-12);
}

TEST(Locomotion, NoOscillationIsNone) {
  const MotionFrames f =
      ladder_swim([](int, double) -> std::array<double, 2> { return {0.0, 0.0}; });
  const LocomotionMode m = classify_motion(f, ladder_springs(), 0.0);
  EXPECT_EQ(m.mode, Locomotion::none);
  EXPECT_EQ(m.frames, 300);  // the second half
}

TEST(Locomotion, OneWaggingEndIsATailAndTwoAreProtrusions) {
  const auto wag = [](bool both) {
    return [both](int cell, double t) -> std::array<double, 2> {
      const bool end = cell / 2 == 9 || (both && cell / 2 == 0);
      return {0.0, end ? 0.4 * std::sin(kOmega * t) : 0.0};
    };
  };
  const LocomotionMode tail = classify_motion(ladder_swim(wag(false)), ladder_springs(), kOmega);
  EXPECT_EQ(tail.mode, Locomotion::tail) << locomotion_name(tail.mode);
  EXPECT_EQ(tail.groups, 1);
  EXPECT_GE(tail.contrast, 3.5);
  const LocomotionMode two = classify_motion(ladder_swim(wag(true)), ladder_springs(), kOmega);
  EXPECT_EQ(two.mode, Locomotion::protrusions) << locomotion_name(two.mode);
  EXPECT_EQ(two.groups, 2);
}

TEST(Locomotion, ClassifiesTheSameUnderTheBendingRule) {
  // A travelling contraction wave is no bending wave, and the bending test changes no other number.
  const MotionFrames f = ladder_swim([](int cell, double t) -> std::array<double, 2> {
    return {0.2 * std::sin(kOmega * t - 0.6 * (cell / 2)), 0.0};
  });
  const LocomotionMode plain = classify_motion(f, ladder_springs(), kOmega);
  const LocomotionMode bend = classify_motion(f, ladder_springs(), kOmega, 4.0, true);
  EXPECT_TRUE(bend.has_bend);
  EXPECT_EQ(bend.mode, plain.mode);
  EXPECT_EQ(bend.wave.fit, plain.wave.fit);
  EXPECT_FALSE(bend.bend.is_wave);
  EXPECT_TRUE(std::isnan(bend.bend.p_value));  // fit, lag, TI or direction fail: no shuffles
}

TEST(Locomotion, DominantFrequencyIsTheAmplitudeWeightedMedian) {
  Vector a(4), f(4);
  a << 0.1, 0.0, 0.3, 0.1;
  f << 2.0, 9.0, 5.0, 7.0;
  EXPECT_DOUBLE_EQ(dominant_frequency(a, f), 5.0);  // cumulative 0.1, 0.4 >= 0.25 at f = 5
  EXPECT_EQ(dominant_frequency(Vector::Zero(3), f.head(3)), 0.0);
}

TEST(Locomotion, WindowStartCoversTheClassifiersWindow) {
  // 4000 steps of 1/60: 4 periods of 2π/3 are 502.7 steps, so frames from step 3497 on.
  const int first = window_start_step(4000, 1.0 / 60, 3.0);
  EXPECT_GE(first, 3490);
  EXPECT_LE(first, 3498);
}

TEST(Locomotion, TheWindowsFramesAloneClassifyAsTheWholeRecord) {
  // A recorder keeps the frames from window_start_step() on and says when the swim started.
  const MotionFrames whole = ladder_swim([](int cell, double t) -> std::array<double, 2> {
    return {0.2 * std::sin(kOmega * t - 0.6 * (cell / 2)), 0.05 * std::sin(kOmega * t + cell)};
  });
  const int first = window_start_step(whole.frame_count() - 1, kDt, kOmega);
  MotionFrames end;
  end.cells = whole.cells;
  end.swim_start = 0.0;
  end.times.assign(whole.times.begin() + first, whole.times.end());
  end.xy.assign(whole.xy.begin() + static_cast<std::ptrdiff_t>(first) * 2 * whole.cells,
                whole.xy.end());
  const LocomotionMode a = classify_motion(whole, ladder_springs(), kOmega, 4.0, true);
  const LocomotionMode b = classify_motion(end, ladder_springs(), kOmega, 4.0, true);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_LT(b.frames, end.frame_count() + 1);
  EXPECT_EQ(a.mode, b.mode);
  EXPECT_EQ(a.deformation, b.deformation);
  EXPECT_EQ(a.wave.fit, b.wave.fit);
  EXPECT_EQ(a.bend.fit, b.bend.fit);
  EXPECT_EQ(a.phases, b.phases);
  // Without swim_start the end alone is a shorter swim: its second half holds fewer periods.
  end.swim_start = std::numeric_limits<double>::quiet_NaN();
  EXPECT_LT(classify_motion(end, ladder_springs(), kOmega).cycles, 4.0);
  end.swim_start = end.times.front() + kDt;
  EXPECT_THROW((void)classify_motion(end, ladder_springs(), kOmega), std::invalid_argument);
}

TEST(Locomotion, WindowStartForTheDefaultSwim) {
  // 4000 steps of 1/60 (the defaults): at f = 6, 4 periods are 251.3 steps; at f = 0.5 the second
  // half holds 2 whole periods, 1508.0 steps (+ 1 frame of margin). A recorder of steps / 2 + 2
  // frames always suffices.
  EXPECT_EQ(4000 - window_start_step(4000, 1.0 / 60, 6.0) + 1, 253);
  EXPECT_EQ(4000 - window_start_step(4000, 1.0 / 60, 0.5) + 1, 1509);
  for (double f : {0.5, 0.51, 0.7, 1.0, 3.0, 6.0, 0.0})
    EXPECT_LE(4000 - window_start_step(4000, 1.0 / 60, f) + 1, 4000 / 2 + 2) << f;
}

TEST(Locomotion, RefusesTooFewFramesAndBadSprings) {
  MotionFrames f = ladder_swim([](int, double) -> std::array<double, 2> { return {0.0, 0.0}; });
  IndexPairs bad(1, 2);
  bad << 0, 20;
  EXPECT_THROW((void)classify_motion(f, bad, kOmega), std::invalid_argument);
  f.times.resize(7);
  f.xy.resize(7 * 40);
  EXPECT_THROW((void)classify_motion(f, ladder_springs(), kOmega), std::invalid_argument);
}

}  // namespace
}  // namespace animat
