"""docs/model.md is assembled from the per-stage notes in docs/notes/ (scripts/assemble_model_doc.sh):
an edit made to one and not the other would leave two versions of the model's documentation."""

import shutil
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_model_doc_is_the_assembled_notes(tmp_path):
    (tmp_path / "docs").mkdir()
    shutil.copytree(REPO / "docs" / "notes", tmp_path / "docs" / "notes")
    (tmp_path / "scripts").mkdir()
    shutil.copy(REPO / "scripts" / "assemble_model_doc.sh", tmp_path / "scripts")
    subprocess.run(["bash", "scripts/assemble_model_doc.sh"], cwd=tmp_path, check=True, capture_output=True)
    assembled = (tmp_path / "docs" / "model.md").read_text(encoding="utf-8")
    assert assembled == (REPO / "docs" / "model.md").read_text(encoding="utf-8"), (
        "docs/model.md differs from docs/notes/*.md: edit the notes and run scripts/assemble_model_doc.sh"
    )
