#pragma once
// The locomotion mode of a swim (undulation, synchronous contraction, protrusions, tail, other,
// none), classified from frames of the swim as animat.locomotion classifies them.

namespace animat {}  // namespace animat
