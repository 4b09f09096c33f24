#include "animat/config.hpp"

#include <fmt/format.h>

#include <toml++/toml.h>
#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <type_traits>

#include "animat/errors.hpp"
#include "animat/islands.hpp"
#include "animat/objective.hpp"
#include "animat/search.hpp"

namespace animat {

namespace {

// Calls f(section, info, value) for every field of the config.
template <class C, class F>
void for_each_field(C& config, F&& f) {
  visit_sections(config, [&](std::string_view section, auto& params) {
    visit_fields(params, [&](const FieldInfo& info, auto& value) { f(section, info, value); });
  });
}

// Calls f(info, value) for the field "section.key"; returns false if there is none.
template <class F>
bool with_field(Config& config, std::string_view section, std::string_view key, F&& f) {
  bool found = false;
  for_each_field(config, [&](std::string_view s, const FieldInfo& info, auto& value) {
    if (!found && s == section && info.name == key) {
      found = true;
      f(info, value);
    }
  });
  return found;
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

std::string suggestion(std::string_view word, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_d = 4;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best_d) {
      best_d = d;
      best = c;
    }
  }
  return best.empty() ? std::string{} : fmt::format(" (did you mean '{}'?)", best);
}

std::vector<std::string> section_names() {
  std::vector<std::string> out;
  Config c;
  visit_sections(c, [&](std::string_view s, auto&) { out.emplace_back(s); });
  return out;
}

std::vector<std::string> field_names(std::string_view section) {
  std::vector<std::string> out;
  Config c;
  for_each_field(c, [&](std::string_view s, const FieldInfo& info, auto&) {
    if (s == section) out.emplace_back(info.name);
  });
  return out;
}

template <class T>
constexpr std::string_view type_name() {
  if constexpr (std::is_same_v<T, bool>)
    return "a boolean (true or false)";
  else if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::int64_t>)
    return "an integer";
  else if constexpr (std::is_same_v<T, double>)
    return "a number";
  else if constexpr (std::is_same_v<T, std::string>)
    return "a string";
  else if constexpr (std::is_same_v<T, std::vector<std::string>>)
    return "an array of strings";
  else
    return "an array of numbers";
}

std::string format_double(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, x);  // shortest round-trip form
  std::string s(buf, end);
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  return s;
}

std::string quote(std::string_view s) {
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + "\"";
}

std::string format_value(const auto& value) {
  using T = std::decay_t<decltype(value)>;
  if constexpr (std::is_same_v<T, bool>)
    return value ? "true" : "false";
  else if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::int64_t>)
    return std::to_string(value);
  else if constexpr (std::is_same_v<T, double>)
    return format_double(value);
  else if constexpr (std::is_same_v<T, std::string>)
    return quote(value);
  else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    std::vector<std::string> q;
    for (const auto& s : value) q.push_back(quote(s));
    return fmt::format("[{}]", fmt::join(q, ", "));
  } else {
    std::vector<std::string> q;
    for (double d : value) q.push_back(format_double(d));
    return fmt::format("[{}]", fmt::join(q, ", "));
  }
}

// Checks a value against the field's bounds/choices; returns an empty string if fine.
template <class T>
std::string check(const FieldInfo& info, const T& value) {
  auto check_number = [&](double x) -> std::string {
    if (!std::isfinite(x)) return fmt::format("must be finite, {}", info.bounds.describe());
    if (!info.bounds.contains(x))
      return fmt::format("out of range: expected {}", info.bounds.describe());
    return {};
  };
  auto allowed = [&](const std::string& s) {
    // A choice ending in '*' admits every value with that prefix (evaluation.objective =
    // "python:NAME").
    return info.choices.empty() ||
           std::any_of(info.choices.begin(), info.choices.end(), [&](std::string_view c) {
             return c == s || (c.ends_with('*') && s.size() >= c.size() &&
                               s.starts_with(c.substr(0, c.size() - 1)));
           });
  };
  if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::int64_t> ||
                std::is_same_v<T, double>) {
    return check_number(static_cast<double>(value));
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!allowed(value)) return fmt::format("expected one of {}", fmt::join(info.choices, ", "));
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      if (!allowed(value[i]))
        return fmt::format("unknown entry {} (expected any of {})", quote(value[i]),
                           fmt::join(info.choices, ", "));
      for (std::size_t j = 0; j < i; ++j)
        if (value[j] == value[i]) return fmt::format("entry {} is listed twice", quote(value[i]));
    }
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    for (double d : value)
      if (auto e = check_number(d); !e.empty())
        return fmt::format("entry {}: {}", format_double(d), e);
  }
  return {};
}

// Reads a TOML node into a field of type T; returns an error text or empty.
template <class T>
std::string read_node(const toml::node& node, T& out) {
  if constexpr (std::is_same_v<T, bool>) {
    if (!node.is_boolean()) return "wrong type";
    out = node.as_boolean()->get();
  } else if constexpr (std::is_same_v<T, int> || std::is_same_v<T, std::int64_t>) {
    if (!node.is_integer()) return "wrong type";
    const std::int64_t v = node.as_integer()->get();
    if constexpr (std::is_same_v<T, int>)
      if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
        return "out of the integer range";
    out = static_cast<T>(v);
  } else if constexpr (std::is_same_v<T, double>) {
    if (node.is_integer())
      out = static_cast<double>(node.as_integer()->get());
    else if (node.is_floating_point())
      out = node.as_floating_point()->get();
    else
      return "wrong type";
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!node.is_string()) return "wrong type";
    out = node.as_string()->get();
  } else {
    const toml::array* arr = node.as_array();
    if (!arr) return "wrong type";
    T result;
    for (const toml::node& el : *arr) {
      typename T::value_type v{};
      if (auto e = read_node(el, v); !e.empty()) return "wrong type";
      result.push_back(std::move(v));
    }
    out = std::move(result);
  }
  return {};
}

std::string node_text(const toml::node& node) {
  std::ostringstream ss;
  if (node.is_string())
    ss << quote(node.as_string()->get());
  else
    node.visit([&](auto&& n) { ss << n; });
  std::string s = ss.str();
  return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

std::string location(std::string_view source, const toml::source_region& r) {
  return r.begin.line ? fmt::format("{}:{}", source, r.begin.line) : std::string(source);
}

void apply_table(Config& config, const toml::table& root, std::string_view source) {
  const auto sections = section_names();
  for (auto&& [skey, snode] : root) {
    const std::string section(skey.str());
    if (std::find(sections.begin(), sections.end(), section) == sections.end())
      throw ConfigError(fmt::format("{}: unknown section [{}]{}; sections are: {}",
                                    location(source, skey.source()), section,
                                    suggestion(section, sections), fmt::join(sections, ", ")));
    const toml::table* table = snode.as_table();
    if (!table)
      throw ConfigError(fmt::format("{}: '{}' must be a table ([{}])",
                                    location(source, snode.source()), section, section));
    for (auto&& [kkey, kvalue] : *table) {
      // a named reference: lambdas may not capture structured bindings before C++20 in clang < 16
      const toml::node& knode = kvalue;
      const std::string key(kkey.str());
      const bool found = with_field(config, section, key, [&](const FieldInfo& info, auto& value) {
        using T = std::decay_t<decltype(value)>;
        T parsed = value;
        const std::string where = fmt::format("{}: {}.{} = {}", location(source, knode.source()),
                                              section, key, node_text(knode));
        if (auto e = read_node(knode, parsed); !e.empty())
          throw ConfigError(fmt::format("{}: {}, expected {}", where, e, type_name<T>()));
        if (auto e = check(info, parsed); !e.empty())
          throw ConfigError(fmt::format("{}: {}", where, e));
        value = std::move(parsed);
      });
      if (!found) {
        const auto names = field_names(section);
        throw ConfigError(fmt::format("{}: unknown key '{}.{}'{}", location(source, kkey.source()),
                                      section, key, suggestion(key, names)));
      }
    }
  }
}

toml::table parse_toml(std::string_view text, std::string_view source) {
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    throw ConfigError(fmt::format("{}:{}:{}: malformed TOML: {}", source, e.source().begin.line,
                                  e.source().begin.column, e.description()));
  }
}

}  // namespace

Config config_from_toml(std::string_view text, std::string_view source) {
  Config config;
  apply_table(config, parse_toml(text, source), source);
  validate(config, source);
  return config;
}

Config load_config(const std::filesystem::path& path) {
  // A directory opens as a stream on Linux and reads as nothing: it would be the default config.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw IoError(fmt::format("{}: cannot read config file: Is a directory", path.string()));
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw IoError(fmt::format("{}: cannot open config file: {}", path.string(),
                              errno ? std::strerror(errno) : "unknown error"));
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad())
    throw IoError(
        fmt::format("{}: cannot read config file: {}", path.string(), std::strerror(errno)));
  return config_from_toml(text, path.string());
}

std::string to_toml(const Config& config, std::string_view version,
                    const std::function<std::string(std::string_view, std::string_view)>& comment) {
  Config copy = config;
  std::string out = fmt::format(
      "# animat {} configuration. Every key is listed with its default or resolved value.\n"
      "# [paper] marks values fixed by Joachimczak & Wrobel (GECCO 2012); [choose] marks project "
      "choices\n"
      "# documented in docs/model.md.\n",
      version);
  std::string_view current;
  for_each_field(copy, [&](std::string_view section, const FieldInfo& info, auto& value) {
    if (section != current) {
      out += fmt::format("\n[{}]\n", section);
      current = section;
    }
    out +=
        fmt::format("# {}\n{} = {}\n", comment(fmt::format("{}.{}", section, info.name), info.doc),
                    info.name, format_value(value));
  });
  return out;
}

std::string to_toml(const Config& config) {
  return to_toml(config, ANIMAT_VERSION,
                 [](std::string_view, std::string_view doc) { return std::string(doc); });
}

namespace {
// One "section.key=value": the value checked on its own (type, range), the cross-key rules not yet.
void apply_override_unvalidated(Config& target, std::string_view assignment) {
  if (assignment.find_first_of("\r\n") != std::string_view::npos)
    throw ConfigError(
        fmt::format("--set {}: one assignment per --set; newlines are not allowed", assignment));
  Config config = target;  // applied to a copy: a rejected override leaves the config unchanged
  const auto eq = assignment.find('=');
  const auto dot = assignment.find('.');
  if (eq == std::string_view::npos || dot == std::string_view::npos || dot > eq)
    throw ConfigError(fmt::format("--set {}: expected section.key=value", assignment));
  auto trim = [](std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
  };
  const std::string section(trim(assignment.substr(0, dot)));
  const std::string key(trim(assignment.substr(dot + 1, eq - dot - 1)));
  std::string value(trim(assignment.substr(eq + 1)));
  // Bare words are accepted for string fields: --set physics.drag_scheme=explicit.
  std::string expected;
  with_field(config, section, key, [&](const FieldInfo&, auto& v) {
    using T = std::decay_t<decltype(v)>;
    expected = type_name<T>();
    if constexpr (std::is_same_v<T, std::string>)
      if (value.empty() || value.front() != '"') value = quote(value);
  });
  const std::string doc = fmt::format("[{}]\n{} = {}\n", section, key, value);
  toml::table table;
  try {
    table = toml::parse(std::string_view(doc), std::string_view("--set"));
  } catch (const toml::parse_error&) {
    if (!expected.empty())
      throw ConfigError(fmt::format("--set {}: '{}' is not a valid value for {}.{} (expected {})",
                                    assignment, value, section, key, expected));
    throw ConfigError(fmt::format("--set {}: malformed value", assignment));
  }
  try {
    apply_table(config, table, "--set");
  } catch (const ConfigError& e) {
    std::string msg = e.what();
    if (msg.rfind("--set:", 0) == 0) msg = msg.substr(msg.find(' ') + 1);
    if (msg.rfind("--set", 0) == 0) msg = msg.substr(msg.find(' ') + 1);
    throw ConfigError(fmt::format("--set {}: {}", assignment, msg));
  }
  target = std::move(config);
}
}  // namespace

void apply_override(Config& target, std::string_view assignment) {
  Config config = target;  // a rejected override leaves the config unchanged
  apply_override_unvalidated(config, assignment);
  validate(config, "--set");
  target = std::move(config);
}

void apply_overrides(Config& target, const std::vector<std::string>& assignments) {
  Config config = target;  // all or nothing
  for (const auto& a : assignments) apply_override_unvalidated(config, a);
  if (!assignments.empty()) validate(config, "--set");
  target = std::move(config);
}

namespace {
std::pair<std::string, std::string> split_key(std::string_view dotted) {
  const auto dot = dotted.find('.');
  if (dot == std::string_view::npos)
    throw ConfigError(fmt::format("config key '{}' must be 'section.key'", dotted));
  return {std::string(dotted.substr(0, dot)), std::string(dotted.substr(dot + 1))};
}
}  // namespace

void set_value(Config& config, std::string_view dotted, const ConfigValue& cv) {
  const auto [section, key] = split_key(dotted);
  const bool found = with_field(config, section, key, [&](const FieldInfo& info, auto& value) {
    using T = std::decay_t<decltype(value)>;
    T parsed{};
    bool ok = true;
    std::visit(
        [&](const auto& x) {
          using X = std::decay_t<decltype(x)>;
          if constexpr (std::is_same_v<T, X>)
            parsed = x;
          else if constexpr ((std::is_same_v<T, int>) && std::is_same_v<X, std::int64_t>) {
            if (x < std::numeric_limits<int>::min() || x > std::numeric_limits<int>::max())
              ok = false;
            else
              parsed = static_cast<T>(x);
          } else if constexpr (std::is_same_v<T, double> && std::is_same_v<X, std::int64_t>)
            parsed = static_cast<T>(x);
          else if constexpr (std::is_same_v<T, std::vector<double>> &&
                             std::is_same_v<X, std::vector<std::string>>)
            ok = x.empty();
          else if constexpr (std::is_same_v<T, std::vector<std::string>> &&
                             std::is_same_v<X, std::vector<double>>)
            ok = x.empty();
          else
            ok = false;
        },
        cv);
    if (!ok && std::is_same_v<T, int> && std::holds_alternative<std::int64_t>(cv))
      throw ConfigError(fmt::format("{} = {}: out of the integer range, expected {}", dotted,
                                    std::get<std::int64_t>(cv), info.bounds.describe()));
    if (!ok)
      throw ConfigError(fmt::format("{} = {}: wrong type, expected {}", dotted,
                                    format_config_value(cv), type_name<T>()));
    if (auto e = check(info, parsed); !e.empty())
      throw ConfigError(fmt::format("{} = {}: {}", dotted, format_value(parsed), e));
    value = std::move(parsed);
  });
  if (!found) {
    std::vector<std::string> keys = config_keys();
    throw ConfigError(fmt::format("unknown config key '{}'{}", dotted, suggestion(dotted, keys)));
  }
}

ConfigValue get_value(const Config& config, std::string_view dotted) {
  const auto [section, key] = split_key(dotted);
  Config copy = config;
  ConfigValue out;
  const bool found = with_field(copy, section, key, [&](const FieldInfo&, auto& value) {
    using T = std::decay_t<decltype(value)>;
    if constexpr (std::is_same_v<T, int>)
      out = static_cast<std::int64_t>(value);
    else
      out = value;
  });
  if (!found) {
    std::vector<std::string> keys = config_keys();
    throw ConfigError(fmt::format("unknown config key '{}'{}", dotted, suggestion(dotted, keys)));
  }
  return out;
}

std::vector<std::string> config_keys() {
  std::vector<std::string> out;
  Config c;
  for_each_field(c, [&](std::string_view s, const FieldInfo& info, auto&) {
    out.push_back(fmt::format("{}.{}", s, info.name));
  });
  return out;
}

std::string config_doc(std::string_view dotted) {
  const auto [section, key] = split_key(dotted);
  Config c;
  std::string doc;
  if (!with_field(c, section, key, [&](const FieldInfo& info, auto&) {
        doc = fmt::format("{} ({})", info.doc, info.bounds.describe());
      }))
    throw ConfigError(fmt::format("unknown config key '{}'", dotted));
  return doc;
}

Identity config_identity(std::string_view dotted) {
  const auto [section, key] = split_key(dotted);
  Config c;
  Identity identity = Identity::defines_run;
  if (!with_field(c, section, key, [&](const FieldInfo& info, auto&) { identity = info.identity; }))
    throw ConfigError(fmt::format("unknown config key '{}'", dotted));
  return identity;
}

void validate(const Config& config, std::string_view source) {
  Config copy = config;
  for_each_field(copy, [&](std::string_view section, const FieldInfo& info, auto& value) {
    if (auto e = check(info, value); !e.empty())
      throw ConfigError(
          fmt::format("{}: {}.{} = {}: {}", source, section, info.name, format_value(value), e));
  });
  auto fail = [&](std::string_view msg) { throw ConfigError(fmt::format("{}: {}", source, msg)); };
  if (config.evolution.elites >= config.evolution.population)
    fail(fmt::format("evolution.elites = {} must be smaller than evolution.population = {}",
                     config.evolution.elites, config.evolution.population));
  if (config.development.stiffness_min > config.development.stiffness_max)
    fail(fmt::format("development.stiffness_min = {} exceeds development.stiffness_max = {}",
                     config.development.stiffness_min, config.development.stiffness_max));
  if (config.development.frequency_min > config.development.frequency_max)
    fail(fmt::format("development.frequency_min = {} exceeds development.frequency_max = {}",
                     config.development.frequency_min, config.development.frequency_max));
  std::size_t specials = 0;
  try {
    specials = enabled_input_channels(config.genome).size() +
               enabled_output_channels(config.genome).size();
  } catch (const ConfigError& e) {
    fail(e.what());  // names genome.extra_inputs / extra_outputs and the value
  }
  if (config.genome.max_elements < 2 * config.genome.initial_units + static_cast<int>(specials))
    fail(fmt::format(
        "genome.max_elements = {} cannot hold a random genome of genome.initial_units = {} units "
        "(needs at least {} elements)",
        config.genome.max_elements, config.genome.initial_units,
        2 * config.genome.initial_units + static_cast<int>(specials)));
  try {
    validate(config.development);
    validate(config.evaluation);
    validate(config.scene);  // its cross-key rules too (e.g. ground friction: mu_k <= mu_s)
    validate(config.physics);
    validate(config.control, config.physics);
  } catch (const ConfigError& e) {
    fail(e.what());
  }
  // [islands]
  if (const std::string e = island_config_error(config.evolution); !e.empty()) fail(e);
  // [search]: the names are checked by the Python tables that own them (animat.qd, animat.moo)
  const SearchParams& search = config.search;
  for (const auto& [key, list] : {std::pair{"descriptors", &search.descriptors},
                                  std::pair{"objectives", &search.objectives}}) {
    if (list->empty()) fail(fmt::format("search.{} = []: name at least one", key));
    for (const auto& name : *list)
      if (name.empty() || name.find_first_of(" \t\n,") != std::string::npos)
        fail(fmt::format("search.{} = {}: entry {} is not a name", key, format_value(*list),
                         quote(name)));
  }
  if (search.bins.size() != 1 && search.bins.size() != search.descriptors.size())
    fail(fmt::format(
        "search.bins = {}: give one count for every descriptor or one for each of the {} of "
        "search.descriptors = {}",
        format_value(search.bins), search.descriptors.size(), format_value(search.descriptors)));
  for (double b : search.bins)
    if (b != std::floor(b))
      fail(fmt::format("search.bins = {}: entry {} is not a whole number",
                       format_value(search.bins), format_double(b)));
  if (!search.ranges.empty() && search.ranges.size() != 2 * search.descriptors.size())
    fail(fmt::format(
        "search.ranges = {}: give lo and hi for each of the {} of search.descriptors = {} ({} "
        "numbers), or [] for the measures table's ranges",
        format_value(search.ranges), search.descriptors.size(), format_value(search.descriptors),
        2 * search.descriptors.size()));
  for (std::size_t j = 0; j + 1 < search.ranges.size(); j += 2)
    if (!std::isfinite(search.ranges[j]) || !std::isfinite(search.ranges[j + 1]) ||
        !(search.ranges[j] < search.ranges[j + 1]))
      fail(fmt::format("search.ranges = {}: the range of \"{}\", [{}, {}], is not finite lo < hi",
                       format_value(search.ranges), search.descriptors[j / 2],
                       format_double(search.ranges[j]), format_double(search.ranges[j + 1])));
  if (search.archive == "cvt") {
    try {
      check_cvt_size(search.descriptors.size(), static_cast<std::size_t>(search.cells),
                     static_cast<std::size_t>(search.samples), "search.cells", "search.samples");
    } catch (const ConfigError& e) {
      fail(e.what());
    }
  }
  if (config.development.min_cells > config.development.max_cells)
    fail(fmt::format("development.min_cells = {} exceeds development.max_cells = {}",
                     config.development.min_cells, config.development.max_cells));
  if (config.evaluation.reference_check != "off" &&
      static_cast<long long>(config.physics.substeps) * config.evaluation.reference_substeps > 1000)
    fail(
        fmt::format("the exploit guard's reference step needs physics.substeps x "
                    "evaluation.reference_substeps = {} x {} "
                    "Box2D steps per control step, more than physics.substeps allows (1000); lower "
                    "one of them or "
                    "set evaluation.reference_check = \"off\"",
                    config.physics.substeps, config.evaluation.reference_substeps));
}

std::vector<std::string> config_differences(const Config& a, const Config& b) {
  std::vector<std::string> out;
  for (const auto& key : config_keys())
    if (get_value(a, key) != get_value(b, key)) out.push_back(key);
  return out;
}

std::string format_config_value(const ConfigValue& value) {
  return std::visit([](const auto& v) { return format_value(v); }, value);
}

std::uint64_t fnv1a(std::string_view text) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char ch : text) {
    h ^= ch;
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::uint64_t config_hash(const Config& config) { return fnv1a(to_toml(config)); }

bool operator==(const Config& a, const Config& b) { return to_toml(a) == to_toml(b); }

}  // namespace animat
