#pragma once
// [search] section of the config: which search algorithm a run from this config uses, and the
// settings of the two that are not the paper's GA. Data only: the searches are search.hpp (C++:
// animat_evolve, whose descriptors and criteria are the measures of search.hpp's table) and
// animat.qd and animat.moo (Python, with their own larger tables of descriptor and objective names;
// docs/search.md). The names are checked where a search is made.
#include <string>
#include <string_view>
#include <vector>

#include "animat/params.hpp"

namespace animat {

inline constexpr std::string_view kSearchAlgorithmNames[] = {"ga", "map_elites", "nsga2"};
inline constexpr std::string_view kSearchArchiveNames[] = {"grid", "cvt"};

struct SearchParams {
  /// "ga": the paper's GA (the evolution section); "map_elites", "nsga2": run by animat_evolve
  /// (search.hpp), `animat evolve`, animat.run_map_elites and animat.run_nsga2 [not in the paper:
  /// "ga"]
  std::string algorithm = "ga";
  /// map_elites: the grid archive's descriptors: names of search.hpp's measures() with a range
  /// (animat_evolve) or of animat.qd.DESCRIPTORS (`animat evolve`)
  std::vector<std::string> descriptors = {"elongation", "protrusions"};
  /// map_elites: bins of each descriptor: one count for all, or one per descriptor
  std::vector<double> bins = {10.0};
  /// map_elites: the grid's range of each descriptor, lo and hi in descriptor order ([lo1, hi1,
  /// lo2, hi2, ...]); [] = the ranges of the measures table
  std::vector<double> ranges = {};
  /// map_elites: offspring per generation; 0 = evolution.population
  int batch = 0;
  /// map_elites: the archive, "grid" (search.bins) or "cvt" (search.cells centroids; search.hpp)
  std::string archive = "grid";
  /// map_elites, archive "cvt": the number of centroids (cells)
  int cells = 100;
  /// map_elites, archive "cvt": the uniform samples whose k-means gives the centroids; 0 =
  /// max(1000, 20 cells)
  int samples = 0;
  /// nsga2: the objectives, "NAME" (the table's sense) or "NAME:max" / "NAME:min": names of
  /// search.hpp's measures() (animat_evolve) or of animat.moo.CRITERIA (`animat evolve`)
  std::vector<std::string> objectives = {"distance:max", "actuation_work_positive:min"};
};

template <class V>
void visit_fields(SearchParams& p, V&& v) {
  v(FieldInfo{"algorithm",
              "the search a run from this config uses: \"ga\" (the paper's GA: the evolution "
              "section's settings), "
              "\"map_elites\" or \"nsga2\" (run by animat_evolve and `animat evolve`; "
              "docs/search.md) [not in the paper: ga]",
              Bounds::any(), kSearchAlgorithmNames, Identity::late},
    p.algorithm);
  v(FieldInfo{"descriptors",
              "map_elites: the grid archive's descriptors (animat_evolve: cells, fitness; "
              "`animat evolve`: names of animat.qd.DESCRIPTORS: cells, elongation, protrusions, "
              "frequency, locomotion, ...)",
              Bounds::any(),
              {},
              Identity::late},
    p.descriptors);
  v(FieldInfo{"bins",
              "map_elites: grid bins per descriptor, integers >= 1: one count for every "
              "descriptor, or one each",
              Bounds::closed(1, 100000),
              {},
              Identity::late},
    p.bins);
  v(FieldInfo{"ranges",
              "map_elites: the grid's range of each descriptor, finite lo < hi pairs in "
              "descriptor order ([lo1, hi1, lo2, hi2, ...]); [] = each descriptor's range in the "
              "measures table (a measure without one then needs a range here)",
              Bounds::any(),
              {},
              Identity::late},
    p.ranges);
  v(FieldInfo{"batch",
              "map_elites: offspring per generation; 0 = evolution.population",
              Bounds::closed(0, 100000),
              {},
              Identity::late},
    p.batch);
  v(FieldInfo{"archive",
              "map_elites: the archive, \"grid\" (search.bins per descriptor) or \"cvt\" "
              "(search.cells centroids of a centroidal Voronoi tessellation; docs/search.md)",
              Bounds::any(), kSearchArchiveNames, Identity::late},
    p.archive);
  v(FieldInfo{"cells",
              "map_elites, archive \"cvt\": the number of centroids (cells); with search.samples "
              "at most 2e9 sample-centroid distances per k-means iteration",
              Bounds::closed(1, 1000000),
              {},
              Identity::late},
    p.cells);
  v(FieldInfo{"samples",
              "map_elites, archive \"cvt\": the uniform samples whose k-means gives the "
              "centroids, at least search.cells; 0 = max(1000, 20 search.cells)",
              Bounds::closed(0, 2000000000),
              {},
              Identity::late},
    p.samples);
  v(FieldInfo{"objectives",
              "nsga2: the objectives, \"NAME\" (the table's sense) or \"NAME:max\" / \"NAME:min\" "
              "(animat_evolve: fitness or the evaluation.objective's name, cells, actuation_work, "
              "actuation_work_positive, actuation_work_absolute, max_speed; `animat evolve`: names "
              "of animat.moo.CRITERIA)",
              Bounds::any(),
              {},
              Identity::late},
    p.objectives);
}

}  // namespace animat
