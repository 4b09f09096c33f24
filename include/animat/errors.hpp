#pragma once
// Exception types. Every message names the file (or source), key or index, and the offending value.
#include <stdexcept>
#include <string>

namespace animat {

/// Base of every error animat throws on purpose.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// Bad configuration: unknown key, wrong type, out-of-range value, malformed TOML.
struct ConfigError : Error {
  using Error::Error;
};
/// Bad genome: malformed JSON, unknown element type, NaN coordinates, absurd size.
struct GenomeError : Error {
  using Error::Error;
};
/// Bad geometric input: NaN or huge coordinates, duplicate points.
struct GeometryError : Error {
  using Error::Error;
};
/// Bad checkpoint or run directory: truncated, hash mismatch, wrong version.
struct CheckpointError : Error {
  using Error::Error;
};
/// File-system failure: missing file, unwritable directory, full disk.
struct IoError : Error {
  using Error::Error;
};
/// The simulation left its valid domain (non-finite state, Box2D speed cap hit).
struct SimulationError : Error {
  using Error::Error;
};

}  // namespace animat
