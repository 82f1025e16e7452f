#!/usr/bin/env python3
"""Damages a ROS bag many ways and runs `uwscan bag import` on each copy (bench/robustness/RESULTS.md).

    bench/robustness/damage_bags.py UWSCAN BAG SCRATCH_DIR [--per-kind N] [--seed S] [--json F]

BAG should be one `uwscan bag export` wrote from a simulated dive (it carries its dive
description, so the import needs no --scanner). Kinds of damage: random bits flipped in the
first 4 KB (the bag header record), in the middle (chunks: connection and message records), in
the index at the end (connection and chunk-info records); the file cut at many lengths; blocks of
zeros. Copies that crashed, hung or failed uncleanly are kept in SCRATCH_DIR/kept/. Each import runs with a 20 s timeout and ends as one of:
  read, identical  exit 0 and the log holds what the intact bag's import holds
  read, said       exit 0, frames left out and said so (their payload's metadata row failed its
                   checksum), every frame kept as it was
  read, silent     exit 0 but frames, navigation or the header differ (damage let through)
  clean error      exit 1 with one line on stderr that names the bag
  unclean error    exit 1 otherwise (several lines, or the bag not named)
  crash            a signal or any other exit code
  hang             still running after 20 s
Exits 1 when any import crashed or hung.
"""
import argparse
import json
import os
import random
import sqlite3
import struct
import subprocess
import sys

TIMEOUT_S = 20
OUTCOMES = ["read, identical", "read, said", "read, silent", "clean error", "unclean error", "crash", "hang"]


def log_content(path):
    """What a dive log holds that a damaged bag could change (not its creation time or producer)."""
    db = sqlite3.connect(path)
    try:
        header = db.execute("SELECT scanner_yaml, scan_pattern_yaml, T_V_C_tx, T_V_C_ty, T_V_C_tz, "
                            "T_V_C_qx, T_V_C_qy, T_V_C_qz, T_V_C_qw FROM header").fetchall()
        # Without their numbers: frames left out renumber the ones after them.
        frames = db.execute("SELECT time_s, command, sweep, peaks_px, image FROM frames "
                            "ORDER BY frame_index").fetchall()
        navigation = db.execute("SELECT * FROM navigation ORDER BY nav_id").fetchall()
        return header, frames, navigation
    finally:
        db.close()


def classify_read(log, reference, stdout):
    """How an import that exited 0 ended, against the intact bag's log."""
    header, frames, navigation = log_content(log)
    if (header, frames, navigation) == reference:
        return "read, identical"
    kept_as_they_were = set(frames) <= set(reference[1]) and len(set(frames)) == len(frames)
    if "left out" in stdout and kept_as_they_were and (header, navigation) == (reference[0], reference[2]):
        return "read, said"
    return "read, silent"


def index_position(data):
    """The bag header's index_pos field: where the index (connections, chunk infos) starts."""
    header_length = struct.unpack_from("<I", data, 13)[0]
    at, end = 17, 17 + header_length
    while at < end:
        field_length = struct.unpack_from("<I", data, at)[0]
        name, _, value = data[at + 4:at + 4 + field_length].partition(b"=")
        if name == b"index_pos":
            return struct.unpack("<Q", value)[0]
        at += 4 + field_length
    raise SystemExit("no index_pos in the bag's header")


def flip_bits(data, begin, end, rng):
    out = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        out[rng.randrange(begin, end)] ^= 1 << rng.randrange(8)
    return bytes(out)


def zero_block(data, rng):
    out = bytearray(data)
    length = rng.choice([16, 512, 4096, 65536])
    at = rng.randrange(0, len(data) - length)
    out[at:at + length] = bytes(length)
    return bytes(out)


def mutants(data, per_kind, rng):
    """(kind, description, bytes) for every damaged copy."""
    size, index = len(data), index_position(data)
    middle = (size // 4, 3 * size // 4)
    for k in range(per_kind):
        yield "bits flipped in the first 4 KB", f"#{k}", flip_bits(data, 0, 4096, rng)
        yield "bits flipped in the middle", f"#{k}", flip_bits(data, middle[0], middle[1], rng)
        yield "bits flipped in the index", f"#{k}", flip_bits(data, index, size, rng)
        yield "zeroed block", f"#{k}", zero_block(data, rng)
    # Cuts: inside the first records, then spread over the file, then inside the index.
    cuts = [0, 1, 12, 13, 16, 100, 4096, 4100, 4200, 5000]
    cuts += [size * i // per_kind for i in range(1, per_kind)]
    cuts += [index + (size - index) * i // 10 for i in range(10)] + [size - 1]
    for cut in sorted(set(cuts)):
        yield "truncated", f"at {cut} of {size} bytes", data[:cut]


def run_import(uwscan, bag, log):
    for suffix in ["", "-wal", "-shm", ".partial"]:
        if os.path.exists(log + suffix):
            os.remove(log + suffix)
    try:
        p = subprocess.run([uwscan, "bag", "import", bag, "-o", log], capture_output=True, timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return "hang", ""
    stderr = p.stderr.decode(errors="replace").strip()
    if p.returncode == 0:
        return "read", p.stdout.decode(errors="replace")
    if p.returncode == 1:
        one_line = stderr.count("\n") == 0 and bag in stderr
        return ("clean error" if one_line else "unclean error"), stderr
    return "crash", f"exit {p.returncode}: {stderr[-300:]}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("uwscan")
    parser.add_argument("bag")
    parser.add_argument("scratch")
    parser.add_argument("--per-kind", type=int, default=40, help="damaged copies per kind (and cuts spread over the file)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json", help="write the counts as JSON")
    a = parser.parse_args()
    os.makedirs(a.scratch, exist_ok=True)
    reference_log = os.path.join(a.scratch, "reference.db")
    outcome, message = run_import(a.uwscan, a.bag, reference_log)
    if outcome != "read":
        raise SystemExit(f"the intact bag does not import: {message}")
    reference = log_content(reference_log)
    data = open(a.bag, "rb").read()
    rng = random.Random(a.seed)
    counts, examples = {}, {}
    damaged_bag = os.path.join(a.scratch, "damaged.bag")
    damaged_log = os.path.join(a.scratch, "damaged.db")
    for kind, what, bytes_ in mutants(data, a.per_kind, rng):
        with open(damaged_bag, "wb") as f:
            f.write(bytes_)
        outcome, message = run_import(a.uwscan, damaged_bag, damaged_log)
        if outcome == "read":
            outcome = classify_read(damaged_log, reference, message)
            message = ""
        counts.setdefault(kind, dict.fromkeys(OUTCOMES, 0))[outcome] += 1
        if outcome in ("unclean error", "crash", "hang"):
            # Kept for a closer look and as regression inputs of the fuzzer.
            kept = os.path.join(a.scratch, "kept", f"{outcome} - {kind} {what}.bag".replace(" ", "_"))
            os.makedirs(os.path.dirname(kept), exist_ok=True)
            os.replace(damaged_bag, kept)
        examples.setdefault((kind, outcome), f"{what}: {message.splitlines()[-1] if message else ''}")
    width = max(len(k) for k in counts)
    print(f"{'damage':<{width}} " + " ".join(f"{o:>15}" for o in OUTCOMES))
    for kind, c in counts.items():
        print(f"{kind:<{width}} " + " ".join(f"{c[o]:>15}" for o in OUTCOMES))
    total = {o: sum(c[o] for c in counts.values()) for o in OUTCOMES}
    print(f"{'total':<{width}} " + " ".join(f"{total[o]:>15}" for o in OUTCOMES))
    for (kind, outcome), example in sorted(examples.items()):
        if outcome not in ("read, identical",):
            print(f"  {kind} / {outcome}: {example}"[:400])
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"counts": counts, "total": total, "per_kind": a.per_kind, "seed": a.seed}, f, indent=1)
    return 1 if total["crash"] + total["hang"] > 0 else 0


if __name__ == "__main__":
    sys.exit(main())
