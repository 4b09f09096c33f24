#!/usr/bin/env bash
# Rebuilds docs/model.md from the per-stage notes in docs/notes/ (each stage keeps its own file).
set -euo pipefail
cd "$(dirname "$0")/.."
{
  cat <<'HEAD'
# The animat model: paper facts and project choices

This is the model as implemented, stage by stage, following the pipeline

    genome ─parse─▶ GRN ─develop (Box2D)─▶ embryo ─Gabriel graph (CGAL)─▶ body ─swim (Box2D + effects)─▶ fitness ─GA─▶

The specification is Joachimczak & Wróbel, "Co-evolution of morphology and control of soft-bodied
multicellular animats" (GECCO 2012). **[paper]** marks what the paper fixes; **[choose]** marks a
gap the paper leaves, with the value we chose and why. Every [choose] value is a config key:
`animat_evolve --print-config` prints them all with their documentation, and each section below names
its TOML section. The per-stage notes live in `docs/notes/` and this page is assembled from them
by `scripts/assemble_model_doc.sh`.

Contents: 1. Genome and GRN · 2. Development · 3. Body · 4. Swimming physics (units and coefficients) · 5. Evolution

HEAD
  for f in genome_grn development body physics evolution; do
    echo
    echo "---"
    echo
    sed 's/^# /## /; s/^## \(.*\)/### \1/' "docs/notes/$f.md" | sed '1s/^### /## /'
  done
} > docs/model.md
echo "docs/model.md: $(wc -l < docs/model.md) lines"
