#pragma once
// A run's identity: a hash of what defines the run, recorded in its checkpoints; a resume must give
// the same. Which keys take part is a flag on each key's descriptor (FieldInfo::identity).
#include <cstdint>
#include <string>
#include <vector>

#include "animat/config.hpp"

namespace animat {

/// The scheme run_identity() computes; a checkpoint records it beside the identity.
inline constexpr int kRunIdentityScheme = 2;

/// Scheme 2: FNV-1a of the lines "section.key = value" (each value in its TOML form), in config
/// order, of every key except the resumable ones, a late key only away from its default, and the
/// island keys only with evolution.islands > 1. Documentation is not part of it: editing what a key
/// means on the page changes no identity.
[[nodiscard]] std::uint64_t run_identity(const Config& config);

/// Scheme 1, that of checkpoints without "identity_scheme" (written before scheme 2): FNV-1a of the
/// config's commented TOML with the comments and version line of that time (frozen in
/// src/run_identity_v1_comments.inc), the resumable keys at their defaults, a late key at its
/// default (and any key newer than scheme 2) left out with its comment, and the island keys without
/// islands.
[[nodiscard]] std::uint64_t run_identity_v1(const Config& config);

/// The keys a resume may change (Identity::resumable: caps, budgets, threads, checkpoint interval,
/// the integrator), in config order; every other key is part of run_identity().
[[nodiscard]] const std::vector<std::string>& resumable_keys();

/// The keys added after runs were first checkpointed (Identity::late), in config order.
[[nodiscard]] const std::vector<std::string>& late_keys();

}  // namespace animat
