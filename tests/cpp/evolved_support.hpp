#pragma once
// The evolved genomes shipped as test data (tests/data/evolved/*.json), with the environment each
// evolved in: the hard cases that selection finds (high frequencies, large amplitudes, collisions).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "animat/body.hpp"
#include "animat/config.hpp"
#include "animat/development.hpp"
#include "animat/genome.hpp"

namespace animat {

/// Evolved genomes shipped as test data (tests/data/evolved/*.json): the environment they evolved
/// in
/// ("drag_normal", "max_cells", "frequency_max", "pressure", "pressure_area_floor") and "genome".
struct Evolved {
  std::string name;
  Config config;
  Genome genome;
};
inline std::vector<Evolved> evolved_genomes() {
  std::vector<Evolved> out;
  const std::filesystem::path dir =
      std::filesystem::path(ANIMAT_SOURCE_DIR) / "tests" / "data" / "evolved";
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    std::ifstream in(f);
    std::stringstream ss;
    ss << in.rdbuf();
    const auto j = nlohmann::json::parse(ss.str());
    Evolved e;
    e.name = f.filename().string();
    e.config.scene.drag_normal = j.at("drag_normal").get<double>();
    e.config.development.max_cells = j.at("max_cells").get<int>();
    e.config.development.frequency_max = j.at("frequency_max").get<double>();
    e.config.scene.pressure = j.at("pressure").get<double>();
    e.config.scene.pressure_area_floor = j.at("pressure_area_floor").get<double>();
    e.genome = genome_from_json(j.at("genome").dump(), e.config.genome, f.string());
    out.push_back(std::move(e));
  }
  return out;
}

/// The body of an evolved test genome.
inline Body body_of(const Evolved& e) {
  const Embryo embryo = develop(e.genome, e.config.genome, e.config.grn, e.config.development);
  if (!embryo.viable) throw std::runtime_error(e.name + " is not viable");
  return build_body(embryo);
}

inline const Evolved& named(const std::vector<Evolved>& all, const std::string& name) {
  for (const auto& e : all)
    if (e.name == name) return e;
  throw std::runtime_error("no test genome " + name);
}

}  // namespace animat
