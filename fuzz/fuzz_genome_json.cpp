// libFuzzer target: the genome JSON loader (genome_from_json).
//
// Failure = a crash, a sanitizer report, an exception other than animat::Error, or a broken oracle:
// a genome the loader accepts must validate, round-trip exactly through to_json, and give a GRN.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "animat/errors.hpp"
#include "animat/genome.hpp"
#include "animat/grn.hpp"
#include "fuzz_util.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animat;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  GenomeParams params;
  params.max_elements = 256;  // keeps every input fast; the cap itself is tested at 10^7 elements
  Genome g;
  try {
    g = genome_from_json(text, params, "fuzz");
  } catch (const Error&) {
    return 0;  // a clear rejection is the expected outcome for most inputs
  }
  try {
    validate(g, params, "accepted");
  } catch (const Error& e) {
    fuzz::fail(std::string("accepted genome does not validate: ") + e.what());
  }
  const Genome back = genome_from_json(to_json(g), params, "round trip");
  if (!(back == g)) fuzz::fail("to_json/genome_from_json round trip changed the genome");
  const Grn grn(g, params);
  (void)grn.has_required_paths();
  return 0;
}
