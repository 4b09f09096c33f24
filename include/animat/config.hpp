#pragma once
// The whole configuration: one params struct per stage, mapped one to one onto TOML sections.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "animat/body.hpp"
#include "animat/control.hpp"
#include "animat/development.hpp"
#include "animat/evaluation_params.hpp"
#include "animat/evolution_params.hpp"
#include "animat/genome.hpp"
#include "animat/grn.hpp"
#include "animat/physics.hpp"
#include "animat/scene.hpp"
#include "animat/search_params.hpp"

namespace animat {

struct Config {
  GenomeParams genome;
  MutationParams mutation;
  GrnParams grn;
  DevelopmentParams development;
  BodyParams body;
  SceneParams scene;
  PhysicsParams physics;
  EvaluationParams evaluation;
  EvolutionParams evolution;
  ControlParams control;
  SearchParams search;
};

/// Calls v(section_name, params) for every section, in TOML order.
template <class C, class V>
void visit_sections(C& c, V&& v) {
  v("genome", c.genome);
  v("mutation", c.mutation);
  v("grn", c.grn);
  v("development", c.development);
  v("body", c.body);
  v("scene", c.scene);
  v("physics", c.physics);
  v("evaluation", c.evaluation);
  v("evolution", c.evolution);
  v("control", c.control);  // after the GA's sections: a run at the defaults hashes as before
  v("search", c.search);    // [control] and [search] existed (their keys are late)
}

/// A config value, as seen by --set and the Python dict view.
using ConfigValue = std::variant<bool, std::int64_t, double, std::string, std::vector<std::string>,
                                 std::vector<double>>;

/// Parses TOML text. Unknown keys, wrong types, out-of-range values and malformed TOML throw
/// ConfigError naming `source`, the line, the key and what was expected. Missing keys keep
/// defaults.
[[nodiscard]] Config config_from_toml(std::string_view text, std::string_view source = "<string>");
[[nodiscard]] Config load_config(const std::filesystem::path& path);
/// The complete config as commented TOML; config_from_toml(to_toml(c)) == c.
[[nodiscard]] std::string to_toml(const Config& config);
/// to_toml() with the version in its first line and each key's comment chosen by the caller:
/// comment(dotted_key, doc) gives the text of the key's comment line.
[[nodiscard]] std::string to_toml(
    const Config& config, std::string_view version,
    const std::function<std::string(std::string_view dotted_key, std::string_view doc)>& comment);
/// Applies "section.key=value"; the value is parsed by the field's type, then the whole config is
/// validated (the cross-key rules included). A rejected override leaves the config unchanged.
void apply_override(Config& config, std::string_view assignment);
/// Applies several assignments in order, then validates once: the cross-key rules (elites <
/// population, ...) see all of them, whatever their order. All or nothing.
void apply_overrides(Config& config, const std::vector<std::string>& assignments);
void set_value(Config& config, std::string_view dotted_key, const ConfigValue& value);
[[nodiscard]] ConfigValue get_value(const Config& config, std::string_view dotted_key);
/// Every "section.key", in order.
[[nodiscard]] std::vector<std::string> config_keys();
[[nodiscard]] std::string config_doc(std::string_view dotted_key);
/// The key's part in a run's identity (its descriptor's FieldInfo::identity); throws ConfigError
/// for an unknown key.
[[nodiscard]] Identity config_identity(std::string_view dotted_key);
/// Checks every field's range and the cross-field rules; throws ConfigError naming the key.
void validate(const Config& config, std::string_view source = "config");
/// The keys whose values differ between a and b, in config order (as "section.key").
[[nodiscard]] std::vector<std::string> config_differences(const Config& a, const Config& b);
/// A value as the TOML form writes it (for messages).
[[nodiscard]] std::string format_config_value(const ConfigValue& value);
/// Stable 64-bit hash of the resolved config (FNV-1a of to_toml).
[[nodiscard]] std::uint64_t config_hash(const Config& config);
/// 64-bit FNV-1a hash of text (config and run identities, checkpoint checksums).
[[nodiscard]] std::uint64_t fnv1a(std::string_view text);

bool operator==(const Config& a, const Config& b);

}  // namespace animat
