"""Regenerates the seed corpora in fuzz/corpus/<target>/ (committed; run this only to refresh them).

    PYTHONPATH=build/python .venv/bin/python fuzz/make_corpus.py

Seeds are small valid inputs (and a few bad ones from tests/bad_inputs/catalogue/) so that libFuzzer
starts from the interesting parts of each format. The first byte of a config, checkpoint or evaluate
seed selects the harness's mode (see the comment at the top of each fuzz_*.cpp).
"""
from __future__ import annotations

import json
import shutil
import struct
import tempfile
from pathlib import Path

import animat

FUZZ = Path(__file__).resolve().parent
CORPUS = FUZZ / "corpus"
CATALOGUE = FUZZ.parent / "tests" / "bad_inputs" / "catalogue"


def write(target: str, name: str, data: bytes | str):
    d = CORPUS / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data.encode() if isinstance(data, str) else data)


def viable_seeds(count: int, steps: int = 300) -> list:
    c = animat.Config()
    c["evaluation.steps"] = steps
    seeds = []
    for start in range(0, 100000, 2000):
        found = animat.evaluate_population([animat.Genome.random(s) for s in range(start, start + 2000)], c)
        seeds += [start + i for i, f in enumerate(found) if f.viable]
        if len(seeds) >= count:
            return seeds[:count]
    return seeds


def main():
    for d in CORPUS.glob("*"):
        shutil.rmtree(d)
    seeds = viable_seeds(6)

    # genome_json: random and viable genomes, a minimal one, bad catalogue genomes.
    for s in seeds[:3]:
        write("genome_json", f"viable_{s}.json", animat.Genome.random(s).to_json())
    write("genome_json", "random_1.json", animat.Genome.random(1).to_json(indent=1))
    write("genome_json", "empty.json", '{"format": "animat.genome", "version": 1, "dimensions": 2, "elements": []}')
    write("genome_json", "dims3.json", '{"format": "animat.genome", "version": 1, "dimensions": 3, "elements": '
          '[{"type": "input", "sign": -1, "channel": "maternal2", "coords": [1, 2.5, -3e-3]}]}')
    for p in sorted(CATALOGUE.glob("genome_*.json"))[:12]:
        write("genome_json", "bad_" + p.name, p.read_bytes())

    # config_toml: '0' + a TOML document, '1' + --set lines.
    write("config_toml", "default.toml", "0" + animat.Config().to_toml())
    write("config_toml", "small.toml", "0[evolution]\npopulation = 12\n[physics]\ndt = 0.01\ndrag_scheme = \"implicit\"\n"
          "[scene]\neffects = [\"springs\", \"drag\"]\n[development]\nmaternal_sources = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]\n")
    write("config_toml", "overrides.txt", "1evolution.population=12\nphysics.dt=0.01\nscene.effects=[\"springs\"]\n"
          "physics.drag_scheme=explicit\ndevelopment.maternal_sources=[1,2,3,4,5,6]\nevolution.elites=11\n")
    for p in sorted(CATALOGUE.glob("config_*.toml"))[:10]:
        write("config_toml", "bad_" + p.name, b"0" + p.read_bytes())

    # checkpoint: a real run with the harness's config (population 4, elites 1, seed 7).
    c = animat.Config()
    c["evolution.population"] = 4
    c["evolution.elites"] = 1
    c["evolution.seed"] = 7
    c["evolution.threads"] = 1
    c["evolution.generations"] = 2
    with tempfile.TemporaryDirectory() as tmp:
        animat.evolve(c, out=tmp)
        text = (Path(tmp) / "checkpoint.json").read_text()
    payload = json.loads(text)["payload"]
    write("checkpoint", "file.json", "0" + text)
    write("checkpoint", "payload.json", "1" + payload)
    write("checkpoint", "payload_object.json", "2" + payload)
    short = json.loads(payload)
    short["population"] = short["population"][:1]
    short["history"] = short["history"][-1:]
    write("checkpoint", "payload_short.json", "2" + json.dumps(short))
    for p in sorted(CATALOGUE.glob("checkpoint_*.json"))[:6]:
        write("checkpoint", "bad_" + p.name, b"0" + p.read_bytes())

    # evaluate: viable genomes as JSON, as 'R' + seed, and a few raw byte strings.
    for s in seeds:
        write("evaluate", f"json_{s}.json", animat.Genome.random(s).to_json())
        write("evaluate", f"seed_{s}.bin", b"R" + struct.pack("<Q", s) + bytes([2, 1, 2, 3, 4, 5, 6, 7, 8] * 3))
    for genome in json.loads(payload)["population"]:
        write("evaluate", f"population_{len(list((CORPUS / 'evaluate').iterdir()))}.json", json.dumps(genome["genome"]))
    write("evaluate", "raw_a.bin", bytes([0x00]) + bytes(range(0, 256, 3)))
    write("evaluate", "raw_b.bin", bytes([0x01]) + bytes((i * 7 + 3) % 256 for i in range(400)))


if __name__ == "__main__":
    main()
