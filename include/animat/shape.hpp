#pragma once
// Shape measures of a body at rest (the paper's §6): elongation, concavity, protrusions and their
// mirror symmetry, computed as animat.shape computes them.

namespace animat {}  // namespace animat
