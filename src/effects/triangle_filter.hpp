#pragma once
// The collisions effect's triangle filter (src/effects/collisions.cpp, step 2 of its class
// comment): whether a triangular region's vertex can come within the band of its opposite edge
// during the rest of a step, and a cheaper test in front of it that only ever rejects triangles the
// full test rejects too, so that the candidates, and every result, stay the same.
#include <algorithm>
#include <cmath>

namespace animat::effects {

/// The full test. (abx, aby), (acx, acy): edges a→b and a→c now; (dbx, dby), (dcx, dcy): how they
/// change over the rest of the step (span·(w_b − w_a), span·(w_c − w_a)). The doubled signed area
/// over the step is c0 + c1·u + c2·u², u in [0, 1]; a vertex is within the band of its opposite
/// edge only if 2·area <= band·|edge|, and every edge length over the step is bounded by its L1
/// length now plus its L1 change. True: no vertex of the triangle can reach the band (the triangle
/// is skipped).
inline bool triangle_stays_clear(double abx, double aby, double acx, double acy, double dbx,
                                 double dby, double dcx, double dcy, double band_max) {
  const double c0 = abx * acy - aby * acx;
  const double c1 = abx * dcy - aby * dcx + dbx * acy - dby * acx;
  const double c2 = dbx * dcy - dby * dcx;
  double lowest = std::min(c0, c0 + c1 + c2);
  if (c2 > 0.0 && c1 < 0.0 && -c1 < 2.0 * c2) lowest = std::min(lowest, c0 - c1 * c1 / (4.0 * c2));
  const double bcx = acx - abx, bcy = acy - aby, dbcx = dcx - dbx, dbcy = dcy - dby;
  const double lmax =
      std::max(std::abs(abx) + std::abs(aby) + std::abs(dbx) + std::abs(dby),
               std::max(std::abs(acx) + std::abs(acy) + std::abs(dcx) + std::abs(dcy),
                        std::abs(bcx) + std::abs(bcy) + std::abs(dbcx) + std::abs(dbcy)));
  return lowest > band_max * lmax;
}

/// The factor of the cheaper test's band term: 4·band_max·(1 + 1e-12).
inline double triangle_band4(double band_max) { return 4.0 * band_max * (1.0 + 1e-12); }

/// The cheaper test: true only where triangle_stays_clear is true. `d` bounds every component of
/// the edges' change (d >= |dbx|, |dby|, |dcx|, |dcy| up to rounding; the collisions effect takes
/// the sum over the three vertices of span·(|w_x| + |w_y|)). With every edge coordinate at most
/// `reach` now, |c1| <= 4·reach·d and |c2| <= 2·d², so the smallest area over the step is at least
/// c0 − (4·reach·d + 2·d²) (the interior minimum c0 − c1²/(4·c2) is only taken when |c1| < 2·c2,
/// and then it is at least c0 − |c1|/2), and lmax is at most 4·reach + 4·d (the edge b→c has
/// coordinates up to 2·reach and changes up to 2·d). The factors 1 ± 1e-12 cover the rounding of
/// both tests (a few 1e-16 relative). NaN anywhere makes it false.
inline bool triangle_surely_clear(double abx, double aby, double acx, double acy, double d,
                                  double band4) {
  const double c0 = abx * acy - aby * acx;
  const double reach =
      std::max(std::max(std::abs(abx), std::abs(aby)), std::max(std::abs(acx), std::abs(acy)));
  const double change = 4.0 * reach * d + 2.0 * d * d;
  return c0 * (1.0 - 1e-12) > change * (1.0 + 1e-12) + band4 * (reach + d);
}

}  // namespace animat::effects
