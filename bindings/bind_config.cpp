#include <nanobind/stl/filesystem.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/string_view.h>
#include <nanobind/stl/variant.h>
#include <nanobind/stl/vector.h>

#include "animat/config.hpp"
#include "animat/errors.hpp"
#include "animat/log.hpp"
#include "bindings.hpp"

namespace nb = nanobind;
using namespace nb::literals;

namespace animat::py {
namespace {

// A live view of one config section: cfg.scene.drag_normal reads and writes
// cfg["scene.drag_normal"].
struct SectionView {
  Config* config;
  std::string name;
};

std::string section_of(const std::string& key) { return key.substr(0, key.find('.')); }

nb::dict to_dict(const Config& c) {
  nb::dict out;
  for (const auto& key : config_keys()) {
    const std::string section = section_of(key);
    if (!out.contains(section.c_str())) out[section.c_str()] = nb::dict();
    nb::dict sec = nb::cast<nb::dict>(out[section.c_str()]);
    sec[key.substr(section.size() + 1).c_str()] = nb::cast(get_value(c, key));
  }
  return out;
}

void update(Config& target, const nb::dict& d) {
  Config c = target;  // all or nothing: a rejected value leaves the config unchanged
  for (auto [k, v] : d) {
    const std::string key = nb::cast<std::string>(k);
    if (nb::isinstance<nb::dict>(v)) {
      for (auto [k2, v2] : nb::cast<nb::dict>(v))
        set_value(c, key + "." + nb::cast<std::string>(k2), nb::cast<ConfigValue>(v2));
    } else {
      set_value(c, key, nb::cast<ConfigValue>(v));
    }
  }
  validate(c, "dict");
  target = std::move(c);
}

}  // namespace

void bind_config(nb::module_& m) {
  nb::class_<SectionView>(m, "ConfigSection",
                          "Attribute view of one config section (e.g. ``config.scene``).")
      .def(
          "__getattr__",
          [](const SectionView& s, const std::string& k) {
            try {
              return get_value(*s.config, s.name + "." + k);
            } catch (const ConfigError& e) {
              // so hasattr/getattr(default) follow the protocol
              throw nb::attribute_error(e.what());
            }
          },
          nb::sig("def __getattr__(self, arg: str, /) -> typing.Any"))
      .def("__setattr__", [](SectionView& s, const std::string& k,
                             const ConfigValue& v) { set_value(*s.config, s.name + "." + k, v); })
      .def("__dir__",
           [](const SectionView& s) {
             std::vector<std::string> out;
             for (const auto& key : config_keys())
               if (section_of(key) == s.name) out.push_back(key.substr(s.name.size() + 1));
             return out;
           })
      .def("__repr__", [](const SectionView& s) {
        std::string out = "<ConfigSection [" + s.name + "]";
        for (const auto& key : config_keys())
          if (section_of(key) == s.name) out += " " + key.substr(s.name.size() + 1);
        return out + ">";
      });

  auto cls =
      nb::class_<Config>(
          m, "Config",
          "The whole configuration: one section per pipeline stage, mapped one to one onto "
          "TOML.\n\n"
          "``Config()`` is the embedded default (the paper's d_N = 2, 32-cell setting).\n"
          "Values are read and written as ``config['scene.drag_normal']`` or\n"
          "``config.scene.drag_normal``; every write is checked against the key's type and range\n"
          "and raises ValueError naming the key.")
          .def(nb::init<>())
          .def(
              "__init__",
              [](Config* c, const nb::dict& d) {
                new (c) Config();
                update(*c, d);
              },
              "values"_a,
              "Build from a nested {section: {key: value}} or flat {'section.key': value} dict.")
          .def_static(
              "from_dict",
              [](const nb::dict& d) {
                Config c;
                update(c, d);
                return c;
              },
              "values"_a,
              "Build from a nested {section: {key: value}} or flat {'section.key': value} dict.")
          .def_static("from_toml", &config_from_toml, "text"_a, "source"_a = "<string>",
                      "Parse TOML text; errors name `source`, the line, the key and the expected "
                      "type or range.")
          .def(
              "to_toml", [](const Config& c) { return to_toml(c); },
              "The complete config as commented TOML (what ``animat_evolve --print-config`` "
              "prints).")
          .def("to_dict", &to_dict, "Nested dict {section: {key: value}}.")
          .def("update", &update, "values"_a, "Set several values from a nested or flat dict.")
          .def(
              "apply_override", [](Config& c, const std::string& a) { apply_override(c, a); },
              "assignment"_a,
              "Apply 'section.key=value' (the value is parsed by the key's type), then validate "
              "the config.")
          .def(
              "apply_overrides",
              [](Config& c, const std::vector<std::string>& a) { apply_overrides(c, a); },
              "assignments"_a,
              "Apply several 'section.key=value' exactly as `animat_evolve --set ... --set ...` "
              "does: all of them, then\n"
              "the cross-key checks once, so their order does not matter. All or nothing.")
          .def(
              "keys", [](const Config&) { return config_keys(); },
              "Every 'section.key', in TOML order.")
          .def("__getitem__", &get_value, "key"_a,
               nb::sig("def __getitem__(self, key: str) -> typing.Any"),
               "The value of 'section.key' (bool, int, float, str or a list).")
          .def("__setitem__", &set_value, "key"_a, "value"_a)
          .def("__contains__",
               [](const Config&, const std::string& k) {
                 const auto keys = config_keys();
                 return std::find(keys.begin(), keys.end(), k) != keys.end();
               })
          .def("__iter__", [](const Config&) { return nb::iter(nb::cast(config_keys())); })
          .def("__len__", [](const Config&) { return config_keys().size(); })
          .def(
              "doc", [](const Config&, const std::string& k) { return config_doc(k); }, "key"_a,
              "What a key means and its allowed range.")
          .def(
              "validate", [](const Config& c) { validate(c); },
              "Check every range and cross-field rule; raises ValueError.")
          .def("hash", &config_hash,
               "Stable 64-bit hash of the resolved config (used by checkpoints).")
          .def("copy", [](const Config& c) { return Config(c); })
          .def("__copy__", [](const Config& c) { return Config(c); })
          .def(
              "__deepcopy__", [](const Config& c, nb::handle) { return Config(c); }, "memo"_a)
          .def("__eq__", [](const Config& a, const Config& b) { return a == b; })
          .def("__repr__", [](const Config& c) {
            return "<animat.Config hash=" + std::to_string(config_hash(c)) + ">";
          });
  Config probe;
  visit_sections(probe, [&](std::string_view name, auto&) {
    const std::string section(name);
    cls.def_prop_ro(
        section.c_str(), [section](Config& c) { return SectionView{&c, section}; },
        nb::keep_alive<0, 1>(), ("The [" + section + "] section as an attribute view.").c_str());
  });

  m.def("load_config", &load_config, "path"_a,
        "Load a TOML config file; raises ValueError naming the file, line and key.");
  m.def("set_log_level", &set_log_level, "level"_a,
        "Set the C++ log level: trace, debug, info, warn, error, critical, off.");
}

}  // namespace animat::py
