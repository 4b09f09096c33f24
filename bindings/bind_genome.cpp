#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/pair.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/tuple.h>
#include <nanobind/stl/variant.h>
#include <nanobind/stl/vector.h>

#include <fmt/format.h>

#include <stdexcept>
#include <variant>

#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/errors.hpp"
#include "animat/genome.hpp"
#include "animat/grn.hpp"
#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace animat::py {
namespace {

template <class T>
using Array1 = nb::ndarray<nb::numpy, T, nb::ndim<1>>;
using Array2 = nb::ndarray<nb::numpy, double, nb::ndim<2>>;

// Copies a vector into a freshly owned numpy array.
template <class T>
nb::object to_numpy(std::vector<T> v, std::initializer_list<std::size_t> shape) {
  auto* heap = new std::vector<T>(std::move(v));
  nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nb::ndarray<nb::numpy, T>(heap->data(), shape.size(), shape.begin(), owner).cast();
}

using RngOrSeed = std::variant<Rng*, std::int64_t>;
Rng resolve(RngOrSeed r) {
  if (auto* p = std::get_if<Rng*>(&r)) return **p;
  const auto seed = std::get<std::int64_t>(r);
  if (seed < 0) throw Error("seed must be a non-negative integer, got " + std::to_string(seed));
  return Rng(static_cast<std::uint64_t>(seed));
}
// A Python int argument that must fit int64: a clear TypeError / OverflowError naming it, never a
// wrap.
std::int64_t int64_argument(const char* name, nb::handle h) {
  if (!PyIndex_Check(h.ptr()))
    throw nb::type_error(fmt::format("Rng.integer: {} must be an integer, got {}", name,
                                     nb::type_name(h.type()).c_str())
                             .c_str());
  nb::object index = nb::steal(PyNumber_Index(h.ptr()));
  if (!index.is_valid()) throw nb::python_error();
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (overflow != 0)
    throw std::overflow_error(
        fmt::format("Rng.integer: {} = {} is outside the 64-bit signed range [-2**63, 2**63-1]",
                    name, nb::str(index).c_str()));
  if (v == -1 && PyErr_Occurred()) throw nb::python_error();
  return static_cast<std::int64_t>(v);
}
// Advances a caller-supplied Rng so that repeated calls draw fresh numbers.
void write_back(RngOrSeed r, const Rng& used) {
  if (auto* p = std::get_if<Rng*>(&r)) **p = used;
}

const Config& cfg(const std::optional<Config>& c, Config& fallback) { return c ? *c : fallback; }

}  // namespace

void bind_genome(nb::module_& m) {
  nb::class_<Rng>(
      m, "Rng",
      "Seeded, splittable random stream (xoshiro256**). Same seed, same numbers, everywhere.")
      .def(nb::init<std::uint64_t>(), "seed"_a = 0)
      .def_static(
          "derive",
          [](std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
            return Rng::derive(seed, a, b);
          },
          "seed"_a, "generation"_a = 0, "index"_a = 0,
          "The stream of individual `index` in `generation` of the run with `seed`.")
      .def(
          "uniform", [](Rng& r) { return r.uniform(); }, "Uniform double in [0, 1).")
      .def(
          "normal", [](Rng& r) { return r.normal(); }, "Standard normal deviate.")
      .def(
          "integer",
          [](Rng& r, nb::handle low, nb::handle high) {
            const std::int64_t a = int64_argument("low", low), b = int64_argument("high", high);
            if (a > b)
              throw nb::value_error(
                  fmt::format("Rng.integer: low = {} exceeds high = {}", a, b).c_str());
            return r.integer(a, b);
          },
          "low"_a, "high"_a,
          "Uniform integer in [low, high] (inclusive), both 64-bit signed; the whole int64 range "
          "is allowed.\n"
          "Raises TypeError for a non-integer, OverflowError beyond int64, ValueError if low > "
          "high.")
      .def(
          "next", [](Rng& r) { return r(); }, "Next raw 64-bit value.")
      .def_prop_rw(
          "state", [](const Rng& r) { return r.state(); },
          [](Rng& r, const Rng::State& s) { r.set_state(s); },
          "The four 64-bit words of the generator state.")
      .def("__eq__", [](const Rng& a, const Rng& b) { return a == b; });

  nb::enum_<ElementType>(m, "ElementType", nb::is_arithmetic(),
                         "Type of a genetic element (paper Fig. 1).")
      .value("promoter", ElementType::promoter)
      .value("internal_gene", ElementType::internal_gene)
      .value("morphogen_gene", ElementType::morphogen_gene)
      .value("input", ElementType::input)
      .value("output", ElementType::output);
  nb::enum_<InputChannel>(m, "InputChannel", nb::is_arithmetic(),
                          "Special inputs: the constant 1 and three maternal morphogens.")
      .value("bias", InputChannel::bias)
      .value("maternal0", InputChannel::maternal0)
      .value("maternal1", InputChannel::maternal1)
      .value("maternal2", InputChannel::maternal2)
      .value("strain", InputChannel::strain,
             "Extension (beyond the paper): mean relative stretch of the cell's springs while "
             "swimming.")
      .value("pressure", InputChannel::pressure,
             "Extension: mean S/S0 of the cell's regions while swimming.")
      .value("chemical", InputChannel::chemical,
             "Extension: the scene's chemical field at the cell while swimming.");
  nb::enum_<OutputChannel>(
      m, "OutputChannel", nb::is_arithmetic(),
      "Special outputs: divide, rotate, grow and the oscillator's amplitude, frequency, phase.")
      .value("divide", OutputChannel::divide)
      .value("rotate", OutputChannel::rotate)
      .value("grow", OutputChannel::grow)
      .value("amplitude", OutputChannel::amplitude)
      .value("frequency", OutputChannel::frequency)
      .value("phase", OutputChannel::phase)
      .value("stiffness", OutputChannel::stiffness,
             "Extension (beyond the paper): reserved for per-cell spring stiffness.")
      .value("actuation", OutputChannel::actuation,
             "Extension: the cell's actuation term under control.mode = \"grn\".");

  nb::class_<Genome>(
      m, "Genome",
      "A linear genome (paper §2.1): elements with a type, a sign (+1/-1), a channel for special\n"
      "elements and a point in an N-dimensional affinity space.")
      .def(nb::init<>())
      .def_static(
          "random",
          [](RngOrSeed rng, std::optional<Config> config) {
            Config fallback;
            Rng r = resolve(rng);
            Genome g = random_genome(cfg(config, fallback).genome, r);
            write_back(rng, r);
            return g;
          },
          "seed"_a, "config"_a = nb::none(),
          "A random genome as the paper seeds it: genome.initial_units units of one promoter and "
          "one gene,\n"
          "plus one special element per input and output channel. `seed` is an int or an "
          "animat.Rng\n"
          "(advanced). Most random genomes are not viable (about 1 in 135): see random_viable.")
      .def_static(
          "random_viable",
          [](RngOrSeed rng, std::optional<Config> config, std::optional<int> max_tries) {
            Config fallback;
            const Config& c = cfg(config, fallback);
            Rng r = resolve(rng);
            const int limit = max_tries.value_or(c.evolution.max_init_tries);
            if (limit < 1)
              throw Error("random_viable: max_tries must be >= 1, got " + std::to_string(limit));
            nb::gil_scoped_release release;
            for (int tries = 1; tries <= limit; ++tries) {
              Genome g = random_genome(c.genome, r);
              if (develop(g, c.genome, c.grn, c.development).viable) {
                nb::gil_scoped_acquire gil;
                write_back(rng, r);
                return std::make_tuple(std::move(g), tries);
              }
            }
            throw Error("random_viable: no viable genome in " + std::to_string(limit) +
                        " tries (evolution.max_init_tries); the development or genome settings "
                        "make viability too rare");
          },
          "seed"_a, "config"_a = nb::none(), "max_tries"_a = nb::none(),
          "The first viable random genome drawn from `seed` (an int or an animat.Rng), as the GA "
          "seeds its\n"
          "initial population: returns (genome, tries), tries = random genomes drawn (the paper: a "
          "few\n"
          "hundred). Viability is the development verdict (paper §5). Raises ValueError after "
          "max_tries\n"
          "(default config.evolution.max_init_tries).")
      .def_static(
          "from_arrays",
          [](Array1<const std::int64_t> types, Array1<const std::int64_t> signs,
             Array1<const std::int64_t> channels,
             nb::ndarray<const double, nb::ndim<2>, nb::c_contig> coords) {
            const std::size_t n = types.shape(0);
            if (signs.shape(0) != n || channels.shape(0) != n || coords.shape(0) != n)
              throw GenomeError(
                  "from_arrays: types, signs, channels and coords must have the same length");
            Genome g;
            g.dimensions = static_cast<int>(coords.shape(1));
            for (std::size_t i = 0; i < n; ++i) {
              if (types(i) < 0 || types(i) >= kElementTypeCount)
                throw GenomeError("from_arrays: element " + std::to_string(i) + ": unknown type " +
                                  std::to_string(types(i)));
              Element e;
              e.type = static_cast<ElementType>(types(i));
              e.sign = static_cast<int>(signs(i));
              e.channel = static_cast<int>(channels(i));
              for (std::size_t k = 0; k < coords.shape(1); ++k) e.coords.push_back(coords(i, k));
              g.elements.push_back(std::move(e));
            }
            validate(g, GenomeParams{.max_elements = 1000000}, "from_arrays");
            return g;
          },
          "types"_a, "signs"_a, "channels"_a, "coords"_a,
          "Build a genome from arrays: types (n,) int (ElementType values), signs (n,) of +1/-1,\n"
          "channels (n,) int (InputChannel/OutputChannel for special elements, else 0), coords (n, "
          "N) float.")
      .def_static(
          "from_json",
          [](const std::string& text) {
            return genome_from_json(text, GenomeParams{.max_elements = 1000000}, "<string>");
          },
          "text"_a, "Parse a genome from JSON; raises ValueError naming the element and field.")
      .def_static(
          "load",
          [](const std::filesystem::path& p) {
            return load_genome(p, GenomeParams{.max_elements = 1000000});
          },
          "path"_a, "Load a genome JSON file.")
      .def(
          "to_json",
          [](const Genome& g, std::optional<int> indent) {
            return to_json(g, indent.value_or(-1));
          },
          "indent"_a = nb::none(), "JSON text (exact round trip).")
      .def("save", &save_genome, "path"_a, "Write the genome as JSON.")
      .def(
          "mutate",
          [](const Genome& g, RngOrSeed rng, std::optional<Config> config) {
            Config fallback;
            const Config& c = cfg(config, fallback);
            Rng r = resolve(rng);
            Genome out = g;
            mutate(out, c.mutation, c.genome, r);
            write_back(rng, r);
            return out;
          },
          "rng"_a, "config"_a = nb::none(),
          "A mutated copy: type changes, sign flips, coordinate moves, duplication and deletion of "
          "series,\n"
          "at the rates of config.mutation. `rng` is an animat.Rng (advanced) or an int seed.")
      .def(
          "crossover",
          [](const Genome& a, const Genome& b, RngOrSeed rng, std::optional<int> points) {
            Rng r = resolve(rng);
            Genome out = crossover(a, b, points.value_or(MutationParams{}.crossover_points), r);
            write_back(rng, r);
            return out;
          },
          "other"_a, "rng"_a, "points"_a = nb::none(),
          "Multipoint crossover with `other`; cut points are shared by both parents, so identical "
          "parents\n"
          "give the same genome.")
      .def(
          "units",
          [](const Genome& g) {
            std::vector<std::pair<std::vector<int>, std::vector<int>>> out;
            for (const auto& u : parse_units(g).units) out.emplace_back(u.promoters, u.genes);
            return out;
          },
          "Regulatory units as (promoter indices, gene indices) pairs, in genome order.")
      .def_prop_ro("dimensions", [](const Genome& g) { return g.dimensions; })
      .def_prop_ro(
          "types",
          [](const Genome& g) {
            std::vector<std::int64_t> v;
            for (const auto& e : g.elements) v.push_back(static_cast<std::int64_t>(e.type));
            return to_numpy(std::move(v), {g.size()});
          },
          "(n,) int64 element types (ElementType values).")
      .def_prop_ro(
          "signs",
          [](const Genome& g) {
            std::vector<std::int64_t> v;
            for (const auto& e : g.elements) v.push_back(e.sign);
            return to_numpy(std::move(v), {g.size()});
          },
          "(n,) int64 signs, +1 or -1.")
      .def_prop_ro(
          "channels",
          [](const Genome& g) {
            std::vector<std::int64_t> v;
            for (const auto& e : g.elements) v.push_back(e.channel);
            return to_numpy(std::move(v), {g.size()});
          },
          "(n,) int64 channels of special elements (0 for others).")
      .def_prop_ro(
          "coords",
          [](const Genome& g) {
            std::vector<double> v;
            for (const auto& e : g.elements) v.insert(v.end(), e.coords.begin(), e.coords.end());
            return to_numpy(std::move(v), {g.size(), static_cast<std::size_t>(g.dimensions)});
          },
          "(n, N) float64 affinity-space coordinates.")
      .def("__len__", &Genome::size)
      .def("__eq__", [](const Genome& a, const Genome& b) { return a == b; })
      // By content, as __eq__: a Python genome never changes (every operator returns a new one),
      // so equal genomes may share a set or a dict key.
      .def("__hash__", [](const Genome& g) { return genome_hash(g); })
      .def("__copy__", [](const Genome& g) { return Genome(g); })
      .def(
          "__deepcopy__", [](const Genome& g, nb::handle) { return Genome(g); }, "memo"_a)
      .def("__repr__", [](const Genome& g) {
        return "<animat.Genome " + std::to_string(g.size()) + " elements, " +
               std::to_string(parse_units(g).units.size()) + " units>";
      });

  m.def(
      "affinity",
      [](double d, std::optional<Config> config) {
        Config fallback;
        return affinity(d, cfg(config, fallback).genome);
      },
      "distance"_a, "config"_a = nb::none(),
      "Affinity weight at a distance: 10 at 0, exponential decay, exactly 0 at "
      "genome.affinity_cutoff.");

  nb::class_<Grn>(m, "Grn", "The gene regulatory network a genome encodes (paper §2.1, eq. 1).")
      .def(
          "__init__",
          [](Grn* self, const Genome& g, std::optional<Config> config) {
            Config fallback;
            new (self) Grn(g, cfg(config, fallback).genome);
          },
          "genome"_a, "config"_a = nb::none())
      .def_prop_ro("unit_count", &Grn::unit_count)
      .def_prop_ro("node_count", &Grn::node_count,
                   "Units plus the outputs (6, or 8 when the genome has an extension output): the "
                   "length of a level vector.")
      .def_prop_ro("morphogen_units", &Grn::morphogen_units,
                   "Units that make a diffusible product.")
      .def(
          "output_index", [](const Grn& g, OutputChannel c) { return g.output_node(c); },
          "channel"_a, "Index of an output in a level vector.")
      .def(
          "edges",
          [](const Grn& g) {
            std::vector<std::int64_t> src, dst;
            std::vector<double> w;
            for (const auto& e : g.edges()) {
              src.push_back(e.source);
              dst.push_back(e.target);
              w.push_back(e.weight);
            }
            const std::size_t k = w.size();
            return nb::make_tuple(to_numpy(std::move(src), {k}), to_numpy(std::move(dst), {k}),
                                  to_numpy(std::move(w), {k}));
          },
          "Edge list (sources, targets, weights). Sources: 0-3 inputs, 4..4+U internal products,\n"
          "4+U..4+2U diffusible products, 4+2U..4+2U+3 the extension inputs strain, pressure, "
          "chemical.\n"
          "Targets: 0..U units, U..node_count outputs.")
      .def("reaches", &Grn::reaches, "channel"_a, "Is there a path from an input to this output?")
      .def(
          "has_required_paths", &Grn::has_required_paths,
          "Viability criterion 1: paths from the inputs to divide, amplitude, frequency and phase.")
      .def("to_dot", &Grn::to_dot, "Graphviz DOT text of the network.")
      .def(
          "network_key",
          [](const Grn& g) {
            const std::string key = g.network_key();
            return nb::bytes(key.data(), key.size());
          },
          "Bytes of everything development and a swim read from the network (units, outputs,\n"
          "morphogen units, edges with their weights' bits): two genomes with equal keys develop\n"
          "and swim identically under development.jitter_stream = \"fixed\".")
      .def(
          "run",
          [](const Grn& g, int steps, std::array<double, 3> maternal,
             std::optional<std::vector<double>> morphogens,
             std::optional<std::vector<double>> initial, std::optional<Config> config) {
            Config fallback;
            const Config& c = cfg(config, fallback);
            if (steps < 0) throw Error("run: steps must be >= 0, got " + std::to_string(steps));
            GrnState s = g.initial_state();
            if (initial) {
              if (initial->size() != s.levels.size())
                throw Error("run: initial has " + std::to_string(initial->size()) +
                            " levels, expected " + std::to_string(s.levels.size()));
              s.levels = *initial;
            }
            if (morphogens && morphogens->size() != g.morphogen_units().size())
              throw Error("run: morphogens has " + std::to_string(morphogens->size()) +
                          " entries, expected " + std::to_string(g.morphogen_units().size()));
            GrnInputs in{maternal, morphogens ? std::span<const double>(*morphogens)
                                              : std::span<const double>{}};
            std::vector<double> out(s.levels);
            for (int k = 0; k < steps; ++k) {
              g.step(s, in, c.grn);
              out.insert(out.end(), s.levels.begin(), s.levels.end());
            }
            return to_numpy(std::move(out), {static_cast<std::size_t>(steps) + 1, s.levels.size()});
          },
          "steps"_a, "maternal"_a = std::array<double, 3>{0, 0, 0}, "morphogens"_a = nb::none(),
          "initial"_a = nb::none(), "config"_a = nb::none(),
          "Step eq. 1 `steps` times with fixed inputs; returns (steps+1, node_count) levels, row 0 "
          "= initial.");
}

}  // namespace animat::py
