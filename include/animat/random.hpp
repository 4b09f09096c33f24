#pragma once
// One seeded, splittable random stream (xoshiro256** seeded through SplitMix64).
//
// Streams are derived from a key path, e.g. Rng::derive(seed, generation, index): the numbers an
// individual sees depend only on (run seed, generation, index), never on the thread that runs it.
// The distributions are implemented here, not taken from <random>, so that the same seed gives the
// same numbers with every standard library.
#include <array>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <numbers>

namespace animat {

class Rng {
 public:
  using result_type = std::uint64_t;
  using State = std::array<std::uint64_t, 4>;

  explicit Rng(std::uint64_t seed = 0) { reseed(seed); }

  /// A stream for the key path (seed, keys...). Different paths give independent streams.
  template <class... Keys>
  static Rng derive(std::uint64_t seed, Keys... keys) {
    std::uint64_t h = mix(seed ^ 0x243f6a8885a308d3ULL);
    ((h = mix(h ^ (static_cast<std::uint64_t>(keys) + 0x9e3779b97f4a7c15ULL))), ...);
    return Rng(h);
  }
  /// A child stream keyed by `key`, derived from this stream's current state (does not advance it).
  [[nodiscard]] Rng split(std::uint64_t key) const {
    return Rng(mix(s_[0] ^ mix(s_[1] ^ mix(s_[2] ^ mix(s_[3] ^ key)))));
  }

  void reseed(std::uint64_t seed) {
    std::uint64_t x = seed;
    for (auto& s : s_) s = splitmix(x);
  }

  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return ~std::uint64_t{0}; }

  result_type operator()() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  /// Uniform double in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>((*this)() >> 11) * 0x1.0p-53; }
  /// Uniform double in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Uniform integer in [0, n) without modulo bias; n > 0 (n = 0 gives 0 and draws nothing).
  std::uint64_t below(std::uint64_t n) {
    if (n == 0) return 0;
    const std::uint64_t limit = max() - max() % n;
    std::uint64_t x;
    do {
      x = (*this)();
    } while (x >= limit);
    return x % n;
  }
  /// Uniform integer in [a, b] inclusive; a <= b (callers check; a > b gives a and draws nothing).
  /// The span is computed in unsigned arithmetic, so the whole int64 range is allowed.
  std::int64_t integer(std::int64_t a, std::int64_t b) {
    if (a > b) return a;
    // b - a, no overflow
    const std::uint64_t span = static_cast<std::uint64_t>(b) - static_cast<std::uint64_t>(a);
    const std::uint64_t offset = span == max() ? (*this)() : below(span + 1);
    // wraps to the exact result
    return static_cast<std::int64_t>(static_cast<std::uint64_t>(a) + offset);
  }
  bool bernoulli(double p) { return uniform() < p; }
  /// Standard normal deviate (Marsaglia polar method, no cached spare: state is only s_).
  double normal() {
    double u, v, s;
    do {
      u = uniform(-1.0, 1.0);
      v = uniform(-1.0, 1.0);
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    return u * std::sqrt(-2.0 * std::log(s) / s);
  }
  double normal(double mean, double sigma) { return mean + sigma * normal(); }

  [[nodiscard]] const State& state() const { return s_; }
  void set_state(const State& s) { s_ = s; }
  friend bool operator==(const Rng&, const Rng&) = default;

 private:
  static constexpr std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static constexpr std::uint64_t splitmix(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  static constexpr std::uint64_t mix(std::uint64_t x) { return splitmix(x); }

  State s_{};
};

}  // namespace animat
