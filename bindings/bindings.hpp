#pragma once
// Each stage binds itself in its own file; module.cpp calls them in pipeline order.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <fmt/format.h>

#include <cstddef>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <unordered_set>

namespace animat {
struct Config;
class Objective;
}  // namespace animat

namespace animat::py {
void bind_config(nanobind::module_& m);
void bind_genome(nanobind::module_& m);
void bind_development(nanobind::module_& m);
void bind_body(nanobind::module_& m);
void bind_physics(nanobind::module_& m);
void bind_evolution(nanobind::module_& m);
void bind_research(nanobind::module_& m);
void bind_locomotion(nanobind::module_& m);

/// A C-contiguous float64 array on the CPU: what the bindings read numbers from.
using FloatArray = nanobind::ndarray<const double, nanobind::c_contig, nanobind::device::cpu>;

/// numpy.ascontiguousarray(obj, dtype=float64), so lists and other dtypes are accepted.
inline FloatArray as_float_array(nanobind::handle obj) {
  const nanobind::module_ np = nanobind::module_::import_("numpy");
  return nanobind::cast<FloatArray>(
      np.attr("ascontiguousarray")(obj, nanobind::arg("dtype") = np.attr("float64")));
}

/// The objective `objective` names: None = the config's (evaluation.objective), a str = that
/// built-in, otherwise a Python objective object (name, every, callable with an EvaluationRecord).
std::shared_ptr<const Objective> objective_from_python(nanobind::handle objective,
                                                       const Config& config);

/// The KeyboardInterrupt that a Python objective raised while it scored a genome (Ctrl-C while it
/// ran), taken from it (later calls return nothing); nothing for a built-in objective. Called with
/// the GIL held. Such an objective throws animat::Interrupted, which stops a run like a signal
/// does.
std::optional<nanobind::python_error> take_interrupt(
    const std::shared_ptr<const Objective>& objective);
/// A read-only property `name` of `cls` returning a copy of `field`, a member of the record `probe`
/// (found by its offset): the way a record's visit_fields descriptor becomes its Python properties.
template <class Record, class Class, class T>
void def_field_property(Class& cls, const Record& probe, const T& field, const char* name,
                        const char* doc) {
  const std::ptrdiff_t offset =
      reinterpret_cast<const char*>(&field) - reinterpret_cast<const char*>(&probe);
  cls.def_prop_ro(
      name,
      [offset](const Record& r) -> T {
        return *reinterpret_cast<const T*>(reinterpret_cast<const char*>(&r) + offset);
      },
      doc);
}

/// Holds an object that is not thread-safe for the duration of one bound method (which may run
/// without the GIL); a second thread gets a RuntimeError "animat.KIND.METHOD: MESSAGE" instead of a
/// data race.
template <class T>
class ThreadLease {
 public:
  ThreadLease(const T& object, const char* kind, const char* method, const char* message)
      : object_(&object) {
    std::lock_guard<std::mutex> lock(mutex());
    if (!busy().insert(object_).second)
      throw std::runtime_error(fmt::format("animat.{}.{}: {}", kind, method, message));
  }
  ~ThreadLease() {
    std::lock_guard<std::mutex> lock(mutex());
    busy().erase(object_);
  }
  ThreadLease(const ThreadLease&) = delete;
  ThreadLease& operator=(const ThreadLease&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static std::unordered_set<const T*>& busy() {
    static std::unordered_set<const T*> set;
    return set;
  }
  const T* object_;
};

}  // namespace animat::py
