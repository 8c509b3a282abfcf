#!/usr/bin/python3
"""Writes the seeds of the checkpoint fuzz target (tests/fuzz/checkpoint.cpp) into tests/fuzz/corpus/checkpoint/:
checkpoints of its four scenes, run by `haet run` for 5 ms with checkpoint_period = 5 ms, the last one taken. Run it
after every change of the checkpoint format (io/checkpoint.hpp, kCheckpointVersion), so that the seeds are of the
format the program writes and the fuzzer reaches the sections.

    tests/fuzz/make_checkpoint_seeds.py BUILD_DIR/haet

Each scene gives NAME_file.haet (first byte 1: the whole file) and NAME_body.haet (first byte 0: the body, which the
target seals with a valid header); tdm3 also tdm3_truncated.haet, its file cut halfway. The other seeds of the folder
are inputs the fuzzer once found (far_position, huge_radius_edm) or made by hand (future_version): left as they are.
"""
import pathlib
import subprocess
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent
EXAMPLES = HERE.parent.parent / "examples"
CORPUS = HERE / "corpus" / "checkpoint"
PREFIX = 24  # magic (8), version (4), body length (8), CRC-32 (4)

SCENES = {
    "tdm3": ("drop3d_tiny.toml", []),
    "edm3": ("drop3d_tiny.toml", ["method=edm"]),
    "tdm2": ("elastic_gas2d.toml", ["insert[1].count=8"]),
    "edm2": ("elastic_gas2d.toml", ["insert[1].count=8", "method=edm"]),
}


def checkpoint(haet, scene, sets, tmp):
    out = pathlib.Path(tmp) / "run"
    args = [haet, "run", str(EXAMPLES / scene), "--out", str(out), "--quiet"]
    for kv in sets + ["duration=0.005", "output.checkpoint_period=0.005"]:
        args += ["--set", kv]
    subprocess.run(args, check=True)
    return sorted(out.glob("checkpoint_*.haet"))[-1].read_bytes()


def main():
    if len(sys.argv) != 2:
        print("usage: make_checkpoint_seeds.py BUILD_DIR/haet", file=sys.stderr)
        return 2
    haet = sys.argv[1]
    for name, (scene, sets) in SCENES.items():
        with tempfile.TemporaryDirectory() as tmp:
            whole = checkpoint(haet, scene, sets, tmp)
        assert whole[:8] == b"HAETCKPT"
        (CORPUS / f"{name}_file.haet").write_bytes(b"\x01" + whole)
        (CORPUS / f"{name}_body.haet").write_bytes(b"\x00" + whole[PREFIX:])
        if name == "tdm3":
            (CORPUS / "tdm3_truncated.haet").write_bytes(b"\x01" + whole[:len(whole) // 2])
        print(f"{name}: {len(whole)} bytes")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
