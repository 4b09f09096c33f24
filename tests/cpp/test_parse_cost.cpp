// The bounded JSON parser (genome files, checkpoints) is linear in the input, proven by counting
// work, not by timing it: docs/reliability.md, "Resource bounds".
//
//   ParseCost.*   detail::parse_bounded parses into a basic_json whose arrays count every iterator
//                 step taken over them. A linear parser builds each array by appending and never
//                 walks back over what it built; nlohmann's parse with a callback (what
//                 parse_bounded used before cd57c5a) walks the whole enclosing array each time an
//                 element object closes, n^2/2 steps for n elements: a 99 MB genome file took
//                 minutes before being refused. The count is the same on any machine and under any
//                 load.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "../../src/json_util.hpp"
#include "animat/genome.hpp"
#include "animat/random.hpp"

namespace {

long long g_array_steps = 0;  // iterator moves over StepCountedVector arrays (single-threaded test)

/// A random-access iterator that counts each move (++, --, +=, -=) of the iterator it wraps.
template <class Base>
class StepCounted {
 public:
  using iterator_category = std::random_access_iterator_tag;
  using value_type = typename std::iterator_traits<Base>::value_type;
  using difference_type = typename std::iterator_traits<Base>::difference_type;
  using pointer = typename std::iterator_traits<Base>::pointer;
  using reference = typename std::iterator_traits<Base>::reference;

  StepCounted() = default;
  explicit StepCounted(Base it) : it_(it) {}
  template <class Other>
    requires(!std::is_same_v<Other, Base> && std::is_convertible_v<Other, Base>)
  StepCounted(const StepCounted<Other>& other) : it_(other.base()) {}  // iterator -> const_iterator

  [[nodiscard]] Base base() const { return it_; }
  reference operator*() const { return *it_; }
  pointer operator->() const { return std::to_address(it_); }
  reference operator[](difference_type n) const { return it_[n]; }
  StepCounted& operator++() { return *this += 1; }
  StepCounted operator++(int) {
    StepCounted old = *this;
    *this += 1;
    return old;
  }
  StepCounted& operator--() { return *this += -1; }
  StepCounted operator--(int) {
    StepCounted old = *this;
    *this += -1;
    return old;
  }
  StepCounted& operator+=(difference_type n) {
    ++g_array_steps;
    it_ += n;
    return *this;
  }
  StepCounted& operator-=(difference_type n) { return *this += -n; }
  friend StepCounted operator+(StepCounted a, difference_type n) { return a += n; }
  friend StepCounted operator+(difference_type n, StepCounted a) { return a += n; }
  friend StepCounted operator-(StepCounted a, difference_type n) { return a -= n; }
  template <class Other>
  friend difference_type operator-(const StepCounted& a, const StepCounted<Other>& b) {
    return a.base() - b.base();
  }
  template <class Other>
  friend bool operator==(const StepCounted& a, const StepCounted<Other>& b) {
    return a.base() == b.base();
  }
  template <class Other>
  friend auto operator<=>(const StepCounted& a, const StepCounted<Other>& b) {
    return a.base() <=> b.base();
  }

 private:
  Base it_{};
};

/// std::vector whose iterators, as the JSON library sees them, count their moves. Its own members
/// (push_back, back, the destructor...) use std::vector's iterators and count nothing.
template <class T, class Alloc = std::allocator<T>>
class StepCountedVector : public std::vector<T, Alloc> {
  using Base = std::vector<T, Alloc>;

 public:
  using iterator = StepCounted<typename Base::iterator>;
  using const_iterator = StepCounted<typename Base::const_iterator>;
  using reverse_iterator = std::reverse_iterator<iterator>;
  using const_reverse_iterator = std::reverse_iterator<const_iterator>;
  using Base::Base;

  iterator begin() noexcept { return iterator(Base::begin()); }
  iterator end() noexcept { return iterator(Base::end()); }
  const_iterator begin() const noexcept { return const_iterator(Base::begin()); }
  const_iterator end() const noexcept { return const_iterator(Base::end()); }
  const_iterator cbegin() const noexcept { return begin(); }
  const_iterator cend() const noexcept { return end(); }
  reverse_iterator rbegin() noexcept { return reverse_iterator(end()); }
  reverse_iterator rend() noexcept { return reverse_iterator(begin()); }
  const_reverse_iterator rbegin() const noexcept { return const_reverse_iterator(end()); }
  const_reverse_iterator rend() const noexcept { return const_reverse_iterator(begin()); }
  iterator erase(const_iterator pos) { return iterator(Base::erase(pos.base())); }
  iterator erase(const_iterator first, const_iterator last) {
    return iterator(Base::erase(first.base(), last.base()));
  }
  template <class... Args>
  iterator insert(const_iterator pos, Args&&... args) {
    return iterator(Base::insert(pos.base(), std::forward<Args>(args)...));
  }
  template <class... Args>
  iterator emplace(const_iterator pos, Args&&... args) {
    return iterator(Base::emplace(pos.base(), std::forward<Args>(args)...));
  }
};

using CountingJson = nlohmann::basic_json<std::map, StepCountedVector>;

/// What parse_bounded was before cd57c5a (nlohmann's parse with a callback enforcing the same
/// caps), kept here as the canary below: proof that the count sees the walk that made it quadratic.
template <class Json>
Json parse_with_callback(std::string_view text, int max_depth, int item_depth,
                         long long max_items) {
  long long items = 0;
  auto callback = [&](int depth, nlohmann::detail::parse_event_t event, Json&) {
    using E = nlohmann::detail::parse_event_t;
    if ((event == E::object_start || event == E::array_start) && depth >= max_depth)
      throw animat::detail::JsonLimit("nesting deeper than " + std::to_string(max_depth) +
                                      " levels");
    if (max_items >= 0 && event == E::object_end && depth == item_depth && ++items > max_items)
      throw animat::detail::JsonLimit("more than " + std::to_string(max_items) + " items");
    return true;
  };
  return Json::parse(text.begin(), text.end(), callback);
}

/// A genome file of `n` elements, written by the genome writer itself.
std::string genome_text(int n) {
  animat::Rng rng = animat::Rng::derive(20261126, 1);
  const animat::Genome seed = animat::random_genome(animat::GenomeParams{}, rng);
  animat::Genome g;
  g.dimensions = seed.dimensions;
  for (int i = 0; i < n; ++i)
    g.elements.push_back(seed.elements[static_cast<std::size_t>(i) % seed.size()]);
  return animat::to_json(g);
}

/// The iterator steps over arrays that `parse` takes on `text`, and the parsed document as text.
template <class Parse>
std::pair<long long, std::string> steps_to_parse(const std::string& text, Parse parse) {
  g_array_steps = 0;
  const CountingJson j = parse(text);
  // before j is destroyed (destruction walks each array once)
  const long long steps = g_array_steps;
  return {steps, j.dump()};
}

}  // namespace

TEST(ParseCost, ParsingAGenomeNeverWalksBackOverItsElements) {
  // At most one step per element at every size (a linear parser takes none: it appends), where the
  // callback parser took n^2/2: 500,000 at 1,000 elements, 128 million at 16,000.
  for (int n : {1000, 4000, 16000}) {
    SCOPED_TRACE(n);
    const std::string text = genome_text(n);
    const auto [steps, dump] = steps_to_parse(text, [](const std::string& t) {
      // genome_from_json's caps at max_elements 10^6
      return animat::detail::parse_bounded<CountingJson>(t, 16, 2, 2LL * 1'000'000 + 1000);
    });
    std::printf("[ parse    ] %d genome elements (%zu bytes): %lld iterator steps over arrays\n", n,
                text.size(), steps);
    EXPECT_LE(steps, n) << "parse_bounded walked back over built arrays: " << steps
                        << " iterator steps for " << n << " elements (quadratic parsing)";
    EXPECT_EQ(dump, nlohmann::json::parse(text).dump());  // and it parsed the document
  }
}

TEST(ParseCost, ParsingACheckpointShapedDocumentNeverWalksBackOverItsItems) {
  // Checkpoints: an array of objects inside an object (parse_bounded(text, 64), no item cap).
  const int n = 16000;
  std::string text = R"({"population": [)";
  for (int i = 0; i < n; ++i)
    text += (i ? "," : "") +
            std::string(R"({"fitness": 1.5, "viable": true, "genome": {"elements": [0, 1]}})");
  text += "]}";
  const auto [steps, dump] = steps_to_parse(text, [](const std::string& t) {
    return animat::detail::parse_bounded<CountingJson>(t, 64);
  });
  std::printf("[ parse    ] %d checkpoint items: %lld iterator steps over arrays\n", n, steps);
  EXPECT_LE(steps, n);
  EXPECT_EQ(dump, nlohmann::json::parse(text).dump());
}

TEST(ParseCost, CanaryTheCountSeesTheCallbackParsersQuadraticWalk) {
  // The old parser on the same input: the count must exceed the bound above by far, or the tests
  // above could not fail (n^2/2 = 8 million steps at 4,000 elements). Should a later nlohmann stop
  // walking back, this canary fails while parse_bounded is still fine: find another witness then.
  const int n = 4000;
  const auto [steps, dump] = steps_to_parse(genome_text(n), [](const std::string& t) {
    return parse_with_callback<CountingJson>(t, 16, 2, 2LL * 1'000'000 + 1000);
  });
  std::printf(
      "[ parse    ] the callback parser, %d genome elements: %lld iterator steps over arrays\n", n,
      steps);
  EXPECT_GT(steps, 100LL * n) << "the counting array no longer sees the callback parser's walk";
  EXPECT_GE(steps, static_cast<long long>(n) * (n - 1) / 2);
}
