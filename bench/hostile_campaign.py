#!/usr/bin/env python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""Hostile-input campaigns against the surftex command (issue 21 item 7).

Three families, each run through the CLI one process at a time:
  meshes  mutated OFF/OBJ/PLY/STL files        -> surftex repair IN -o OUT/r.ply --report OUT/r.json
  images  mutated PNG/JPEG/TIFF/EXR/BMP files  -> surftex render MESH --texture IN -o OUT/r.png --size 24
  json    mutated constraints and tile.json    -> surftex material-map MESH --tile T --constraints IN -o OUT/m --atlas-size 128

Every run is classified:
  clean_error    exit 2, one `error: ...` line, nothing left in OUT
  unclean_error  exit 2, nothing left, but library text before our `error:` line
  success        exit 0, every expected output present, nothing else in OUT
  crash          killed by a signal, or an exit code other than 0 and 2, or a
                 sanitizer / `terminate called` message
  hang           not finished within --timeout seconds (default 10)
  over_limits    finished, but took more than 10 s (CPU seconds of the run by default,
                 --clock wall for wall time) or 1 GiB of RSS
  silent_misread a meaning-preserving mutation (BOM, CRLF, blanks, comments,
                 number spelling) whose result differs from the seed's
  partial_output something left in OUT after a failure, a missing or extra
                 output after a success, or a staging folder / temporary left
  broken_install the binary could not load its image IO module (a rebuilt
                 module beside an older binary): the run measured nothing
Usage: bench/hostile_campaign.py --binary build/bin/surftex [--server build/bench/hostile_fork_server]
       [--family meshes|images|json|all] [--count N] [--seed S] [--out results.jsonl]
Prints one JSON line per family with the counts (and writes every run to --out);
bench/hostile_campaign.py --summarize LOG... prints the README's table from the logs.
"""
import argparse
import json
import os
import random
import re
import resource
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

DATA = os.environ.get("SURFTEX_SHARED_DATA",
                      os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data"))
GiB = 1 << 30

# ---------------------------------------------------------------- running


SERVER = None  # the fork server (bench/hostile_fork_server.cpp), when --server is given
# What "10 s" means for over_limits: the run's CPU seconds (user + system, all
# threads; default: independent of other work on the machine) or its wall time.
CLOCK = "cpu"


def run(binary, args, out_dir, timeout):
    """Runs surftex once; returns (status, stderr, seconds, max_rss_bytes of that run)."""
    if SERVER is not None:
        err_path = os.path.join(out_dir, "..", "stderr")
        SERVER.stdin.write(json.dumps([err_path, timeout] + args) + "\n")
        SERVER.stdin.flush()
        r = json.loads(SERVER.stdout.readline())
        err = open(err_path, "rb").read(1 << 16).decode("utf-8", "replace")
        status = "hang" if r["hang"] else r["status"]
        return status, err, r["cpu_seconds"] if CLOCK == "cpu" else r["seconds"], r["max_rss_kb"] * 1024
    start = time.monotonic()
    with tempfile.TemporaryFile() as errf:
        p = subprocess.Popen(["nice", "-n", "10", binary] + args, stdout=subprocess.DEVNULL, stderr=errf,
                             preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_AS, (6 * GiB, 6 * GiB)))
        hung = False
        while True:
            pid, st, ru = os.wait4(p.pid, os.WNOHANG)
            if pid == p.pid:
                break
            if time.monotonic() - start > timeout:
                p.send_signal(signal.SIGKILL)
                pid, st, ru = os.wait4(p.pid, 0)
                hung = True
                break
            time.sleep(0.005)
        p.returncode = os.waitstatus_to_exitcode(st)
        errf.seek(0)
        err = errf.read(1 << 16)
    seconds = ru.ru_utime + ru.ru_stime if CLOCK == "cpu" else time.monotonic() - start
    return ("hang" if hung else p.returncode), err.decode("utf-8", "replace"), seconds, ru.ru_maxrss * 1024


def leftovers(out_dir):
    found = []
    for root, dirs, files in os.walk(out_dir):
        for n in dirs + files:
            found.append(os.path.relpath(os.path.join(root, n), out_dir))
    return sorted(found)


def classify(status, err, seconds, rss_delta, out_dir, expected):
    left = leftovers(out_dir)
    if status == "hang":
        return "hang"
    if status < 0 or status not in (0, 2) or "Sanitizer" in err or "terminate called" in err or "runtime error" in err:
        return "crash"
    if "cannot load the image IO module" in err:
        return "broken_install"  # the binary and its image IO module do not match: the campaign measures nothing
    if any(".surftex-" in x for x in left):
        return "partial_output"
    if status == 2:
        if left:
            return "partial_output"
        # Exit 2 with library text before or instead of our one `error:` line.
        outcome = "clean_error" if err.startswith("error: ") else "unclean_error"
    else:
        outcome = "success" if sorted(expected) == [x for x in left if x in expected] and set(left) <= set(
            expected) | {os.path.dirname(e) for e in expected} else "partial_output"
        if outcome == "success" and not all(os.path.exists(os.path.join(out_dir, e)) for e in expected):
            outcome = "partial_output"
    if outcome in ("clean_error", "success") and (seconds > 10 or rss_delta > GiB):
        return "over_limits"
    return outcome

# ---------------------------------------------------------------- mutations

EXTREMES = [b"1e308", b"-1e308", b"1e400", b"nan", b"inf", b"-0", b"0", b"4294967295", b"18446744073709551616",
            b"-1", b"99999999999", b"1e-320", b"0x10", b"", b"2147483648", b"1e200"]


def neutral_text(data, rnd):
    """A meaning-preserving change of a text mesh: (kind, bytes)."""
    kind = rnd.choice(["bom", "crlf", "trailing_blanks", "blank_lines", "leading_blanks"])
    if kind == "bom":
        return kind, b"\xef\xbb\xbf" + data
    if kind == "crlf":
        return kind, data.replace(b"\r\n", b"\n").replace(b"\n", b"\r\n")
    lines = data.split(b"\n")
    if kind == "trailing_blanks":
        return kind, b"\n".join(l + b" \t" if l.strip() else l for l in lines)
    if kind == "leading_blanks":
        return kind, b"\n".join(b"  " + l if l.strip() and not l.startswith(b"ply") else l for l in lines)
    out = []
    for l in lines:
        out.append(l)
        if rnd.random() < 0.2 and l.strip() and not l.startswith((b"ply", b"OFF", b"solid")):
            out.append(b"")
    return kind, b"\n".join(out)


def destructive(data, rnd, text=True):
    kind = rnd.choice(["flip", "insert", "delete", "truncate", "number", "dup_line", "swap_lines", "splice",
                       "repeat_corners", "header_count"] if text else ["flip", "insert", "delete", "truncate",
                                                                        "overwrite32", "splice"])
    b = bytearray(data)
    n = len(b)
    if kind == "flip" and n:
        for _ in range(rnd.randint(1, 8)):
            b[rnd.randrange(n)] ^= 1 << rnd.randrange(8)
    elif kind == "insert":
        pos = rnd.randrange(n + 1)
        b[pos:pos] = bytes(rnd.randrange(256) for _ in range(rnd.randint(1, 16)))
    elif kind == "delete" and n:
        pos = rnd.randrange(n)
        del b[pos:pos + rnd.randint(1, 64)]
    elif kind == "truncate" and n:
        b = b[:rnd.randrange(n)]
    elif kind == "overwrite32" and n >= 4:
        pos = rnd.randrange(n - 3)
        b[pos:pos + 4] = struct.pack("<I", rnd.choice([0, 1, 0x7FFFFFFF, 0xFFFFFFFF, 65000, 1 << 20, rnd.getrandbits(32)]))
    elif kind == "splice" and n:
        a, c = sorted(rnd.randrange(n) for _ in range(2))
        pos = rnd.randrange(n)
        b[pos:pos] = b[a:c][:4096]
    elif kind in ("number", "header_count"):
        nums = [m for m in re.finditer(rb"-?\d+(\.\d+)?(e-?\d+)?", bytes(b))]
        if nums:
            m = nums[0] if kind == "header_count" and rnd.random() < 0.5 else rnd.choice(nums[:50] if kind == "header_count" else nums)
            rep = rnd.choice(EXTREMES)
            b[m.start():m.end()] = rep
    elif kind in ("dup_line", "swap_lines", "repeat_corners"):
        lines = bytes(b).split(b"\n")
        if len(lines) > 2:
            i = rnd.randrange(len(lines))
            if kind == "dup_line":
                lines[i:i] = [lines[i]] * rnd.randint(1, 50)
            elif kind == "swap_lines":
                j = rnd.randrange(len(lines))
                lines[i], lines[j] = lines[j], lines[i]
            else:
                faces = [k for k, l in enumerate(lines) if l.startswith(b"f ") or re.match(rb"^\s*[3-9] ", l)]
                if faces:
                    k = rnd.choice(faces)
                    toks = lines[k].split()
                    lines[k] = b" ".join(toks[:1] + toks[1:] * rnd.randint(2, 2000))
            b = bytearray(b"\n".join(lines))
    return kind, bytes(b)


def png_chunk(kind, body):
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)


def png_with_size(data, rnd):
    """A PNG whose IHDR claims another size (valid CRC): the header check's case."""
    if not data.startswith(b"\x89PNG") or len(data) < 33:
        return "flip", destructive(data, rnd, False)[1]
    w, h = rnd.choice([(16384, 16384), (65000, 4100), (1, 2**31 - 1), (2**31 - 1, 1), (0, 10), (5000, 5000),
                       (rnd.randrange(1, 70000), rnd.randrange(1, 70000))])
    ihdr = struct.pack(">II", w, h) + data[24:29]
    return "png_size", data[:8] + png_chunk(b"IHDR", ihdr) + data[33:]


def image_mutation(data, rnd):
    r = rnd.random()
    if r < 0.08:
        return "neutral_trailer", data + b"\0" * rnd.randint(1, 64) if data.startswith(b"\x89PNG") else data
    if r < 0.25:
        return png_with_size(data, rnd)
    return destructive(data, rnd, False)


def json_mutation(text, rnd):
    r = rnd.random()
    if r < 0.1:
        return "neutral_blanks", re.sub(rb",", b" ,\n ", text)
    if r < 0.2:
        depth = rnd.choice([40, 1000, 100000])
        return "deep", text.replace(b"[", b"[" * depth, 1).replace(b"]", b"]" * depth, 1)
    if r < 0.35:
        nums = list(re.finditer(rb"-?\d+(\.\d+)?(e-?\d+)?", text))
        if nums:
            m = rnd.choice(nums)
            return "extreme_number", text[:m.start()] + rnd.choice(EXTREMES + [b"1e7", b"-1e7", b"1e154"]) + text[m.end():]
    if r < 0.45:
        return "long_polyline", text.replace(b"[[", b"[" + b"[-5,0,0],[5,0,0]," * rnd.choice([10, 1000, 20000]) + b"[", 1)
    return destructive(text, rnd, True)

# ---------------------------------------------------------------- families


def small_files(folder, exts, limit=256 * 1024):
    out = []
    for f in sorted(os.listdir(folder)):
        p = os.path.join(folder, f)
        if f.lower().endswith(exts) and os.path.getsize(p) <= limit:
            out.append(p)
    return out


def mesh_seeds(binary, work):
    """The shared data's meshes up to 64 KB, plus PLY (ascii, binary) and binary STL seeds made here
    (the shared data has no small ones)."""
    seeds = []
    for sub in ("meshes", "broken", "swatches"):
        seeds += small_files(os.path.join(DATA, sub), (".off", ".obj", ".ply", ".stl"), 64 * 1024)
    for src in ("broken/fused_vertices.off", "swatches/tube_ring.off", "broken/quads_to_stitch.off"):
        src = os.path.join(DATA, src)
        if not os.path.exists(src):
            continue
        for ext in (".ply", ".stl"):
            dst = os.path.join(work, "seed_" + os.path.basename(src)[:-4] + ext)
            if subprocess.call([binary, "convert", src, "-o", dst, "-q"], stderr=subprocess.DEVNULL) == 0:
                seeds.append(dst)
    # An ascii PLY with colours and a quad.
    p = os.path.join(work, "seed_ascii.ply")
    open(p, "w").write("ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
                       "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 3\n"
                       "property list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n"
                       "1 1 0 0 0 255\n0 1 0 9 9 9\n0.5 0.5 1 1 2 3\n4 0 1 2 3\n3 0 1 4\n3 1 2 4\n")
    seeds.append(p)
    return seeds


def report_counts(path):
    try:
        with open(path) as f:
            j = json.load(f)
        return (j.get("vertices"), j.get("faces"), j.get("load", {}).get("input_points"),
                j.get("load", {}).get("input_polygons"))
    except Exception:
        return None


def campaign_meshes(args, rnd, work, log):
    seeds = mesh_seeds(args.binary, work)
    reference = {}
    counts = {}
    for i in range(args.count):
        seed = seeds[i % len(seeds)]
        data = open(seed, "rb").read()
        ext = os.path.splitext(seed)[1]
        text = not (ext == ".stl" and b"solid" not in data[:5]) and b"binary_" not in data[:200]
        neutral = text and rnd.random() < 0.15
        kind, mutated = neutral_text(data, rnd) if neutral else destructive(data, rnd, text)
        inp = os.path.join(work, "in" + ext)
        open(inp, "wb").write(mutated)
        out = os.path.join(work, "out")
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        status, err, sec, rss = run(args.binary, ["repair", inp, "-o", os.path.join(out, "r.ply"), "--report",
                                                  os.path.join(out, "r.json"), "-q"], out, args.timeout)
        outcome = classify(status, err, sec, rss, out, ["r.ply", "r.json"])
        if neutral:
            if seed not in reference:
                ref_out = os.path.join(work, "ref")
                shutil.rmtree(ref_out, ignore_errors=True)
                os.makedirs(ref_out)
                st, _, _, _ = run(args.binary, ["repair", seed, "-o", os.path.join(ref_out, "r.ply"), "--report",
                                                os.path.join(ref_out, "r.json"), "-q"], ref_out, args.timeout)
                reference[seed] = (st, report_counts(os.path.join(ref_out, "r.json")) if st == 0 else None)
            ref_status, ref_counts = reference[seed]
            got = report_counts(os.path.join(out, "r.json")) if status == 0 else None
            if status != ref_status or got != ref_counts:
                outcome = "silent_misread" if status == 0 else outcome + "_on_neutral"
        counts[outcome] = counts.get(outcome, 0) + 1
        log.write(json.dumps({"family": "meshes", "seed": os.path.basename(seed), "mutation": kind,
                              "outcome": outcome, "status": status, "seconds": round(sec, 3), "max_rss_mb": round(rss / 2**20),
                              "error": err.strip().splitlines()[0][:200] if err.strip() else ""}) + "\n")
    return counts, len(seeds)


def image_seeds(work):
    seeds = small_files(os.path.join(DATA, "textures"), (".png",), 64 * 1024)
    src = os.path.join(DATA, "textures", "leather_64.png")
    for ext in ("jpg", "tif", "exr", "bmp", "tga"):
        dst = os.path.join(work, "seed." + ext)
        if subprocess.call(["oiiotool", src, "--resize", "32x32", "-o", dst], stderr=subprocess.DEVNULL) == 0:
            seeds.append(dst)
    return seeds


def tiny_mesh(work):
    p = os.path.join(work, "quad.obj")
    open(p, "w").write("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n")
    return p


def campaign_images(args, rnd, work, log):
    seeds = image_seeds(work)
    mesh = tiny_mesh(work)
    counts = {}
    reference = {}
    for i in range(args.count):
        seed = seeds[i % len(seeds)]
        data = open(seed, "rb").read()
        kind, mutated = image_mutation(data, rnd)
        inp = os.path.join(work, "in" + os.path.splitext(seed)[1])
        open(inp, "wb").write(mutated)
        out = os.path.join(work, "out")
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        status, err, sec, rss = run(args.binary, ["render", mesh, "--texture", inp, "-o", os.path.join(out, "r.png"),
                                                  "--size", "24", "-q"], out, args.timeout)
        outcome = classify(status, err, sec, rss, out, ["r.png"])
        if kind.startswith("neutral"):
            if seed not in reference:
                ref = os.path.join(work, "ref.png")
                if os.path.exists(ref):
                    os.remove(ref)
                subprocess.call(["nice", args.binary, "render", mesh, "--texture", seed, "-o", ref, "--size", "24",
                                 "-q"], stderr=subprocess.DEVNULL)
                reference[seed] = open(ref, "rb").read() if os.path.exists(ref) else None
            got = open(os.path.join(out, "r.png"), "rb").read() if status == 0 else None
            if got != reference[seed]:
                outcome = "silent_misread" if status == 0 else outcome + "_on_neutral"
        counts[outcome] = counts.get(outcome, 0) + 1
        log.write(json.dumps({"family": "images", "seed": os.path.basename(seed), "mutation": kind,
                              "outcome": outcome, "status": status, "seconds": round(sec, 3), "max_rss_mb": round(rss / 2**20),
                              "error": err.strip().splitlines()[0][:200] if err.strip() else ""}) + "\n")
    return counts, len(seeds)


CONSTRAINT_SEEDS = [
    b'{\n "effect_radius": 0.6,\n "strokes": [\n  {"faces": [3, 4, 17], "direction": [0, 1, 0]},\n'
    b'  {"polyline": [[0.05, 0.52, 0.8], [0.95, 0.52, 0.1], [0.2, -0.4, 0.3]]}\n ],\n'
    b' "scale": [{"point": [0.0, 0.0, 1.0], "value": 0.4}],\n'
    b' "material": [{"point": [1.0, 0.0, 0], "value": 1}, {"point": [-1, 0, 0], "value": 0.0}]\n}\n',
    b'{"strokes": [{"polyline": [[-1,-1,-1],[1,1,1]]}], "material": [{"point": [0,0,1], "value": 0.5}]}\n',
    b'{}\n',
]
TILE_SEED = (b'{\n "format": "surftex material tile",\n "size": 8,\n "channels": 3,\n "layers": 2,\n'
             b' "layers_per_pair": 1,\n "layer_list": [\n  {"index": 0, "m": 0.0, "file": "layer_000.png"},\n'
             b'  {"index": 1, "m": 1.0, "file": "layer_001.png"}\n ]\n}\n')


def make_tile(work, body=TILE_SEED):
    t = os.path.join(work, "tile")
    os.makedirs(t, exist_ok=True)
    src = os.path.join(DATA, "textures", "leather_64.png")
    for k in range(2):
        dst = os.path.join(t, "layer_%03d.png" % k)
        if not os.path.exists(dst):
            subprocess.call(["oiiotool", src, "--resize", "8x8", "--ch", "R,G,B", "-o", dst], stderr=subprocess.DEVNULL)
    open(os.path.join(t, "tile.json"), "wb").write(body)
    return t


def sphere(work):
    p = os.path.join(work, "sphere.off")
    if os.path.exists(p):
        return p
    # An octahedron subdivided twice, on the unit sphere (128 faces).
    import math
    V = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    F = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    for _ in range(2):
        mid = {}
        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                x = [(V[a][i] + V[b][i]) / 2 for i in range(3)]
                l = math.sqrt(sum(c * c for c in x))
                V.append(tuple(c / l for c in x))
                mid[k] = len(V) - 1
            return mid[k]
        F = [t for a, b, c in F for t in ((a, m(a, b), m(c, a)), (b, m(b, c), m(a, b)), (c, m(c, a), m(b, c)),
                                          (m(a, b), m(b, c), m(c, a)))]
    with open(p, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(V), len(F)))
        for v in V:
            f.write("%.9f %.9f %.9f\n" % v)
        for t in F:
            f.write("3 %d %d %d\n" % t)
    return p


JSON_COMPARED = ("mesh.ply", "mesh.png")  # the mapping (m per vertex) and the baked atlas


def json_reference(args, work, mesh, tile_case, seed):
    """The compared outputs of material-map on the unmutated seed (None where the run failed)."""
    ref = os.path.join(work, "ref")
    shutil.rmtree(ref, ignore_errors=True)
    inp = os.path.join(work, "ref.json")
    tile = make_tile(work, seed) if tile_case else make_tile(work)
    open(inp, "wb").write(CONSTRAINT_SEEDS[1] if tile_case else seed)
    subprocess.call(["nice", args.binary, "material-map", mesh, "--tile", tile, "--constraints", inp, "-o",
                     os.path.join(ref, "m"), "--render-size", "16", "--atlas-size", "128", "-q"],
                    stderr=subprocess.DEVNULL)
    files = [os.path.join(ref, "m", f) for f in JSON_COMPARED]
    return [open(f, "rb").read() if os.path.exists(f) else None for f in files]


def campaign_json(args, rnd, work, log):
    mesh = sphere(work)
    counts = {}
    reference = {}
    for i in range(args.count):
        tile_case = i % 4 == 3
        seed = TILE_SEED if tile_case else CONSTRAINT_SEEDS[i % len(CONSTRAINT_SEEDS)]
        kind, mutated = json_mutation(seed, rnd)
        inp = os.path.join(work, "c.json")
        if tile_case:
            tile = make_tile(work, mutated)
            open(inp, "wb").write(CONSTRAINT_SEEDS[1])
        else:
            tile = make_tile(work)
            open(inp, "wb").write(mutated)
        out = os.path.join(work, "out")
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        status, err, sec, rss = run(args.binary, ["material-map", mesh, "--tile", tile, "--constraints", inp, "-o",
                                                  os.path.join(out, "m"), "--render-size", "16", "--atlas-size", "128", "-q"],
                                    out,
                                    args.timeout)
        expected = ["m/" + f for f in ("mesh.obj", "mesh.mtl", "mesh.glb", "mesh.ply", "render_plain.png",
                                        "render_fixed.png", "render_normalmap.png", "report.json", "state.json")]
        left = leftovers(out)
        expected = [e for e in expected if e in left or status != 0]
        outcome = classify(status, err, sec, rss, out, expected + ["m"])
        if status == 0 and outcome == "partial_output" and all(x.startswith("m") and ".surftex-" not in x for x in left):
            outcome = "success"  # the folder's exact file list varies by option; the staging check above holds
        if status == 2 and "json" in err and re.search(r"\.json: line \d+: field ", err) is None and "layer file" not in err \
                and "cannot open" not in err and "MiB" not in err:
            outcome = "unnamed_error"
        if kind.startswith("neutral"):
            # Blanks around commas change nothing: the mesh and atlas must be the seed's, byte for byte.
            key = "tile" if tile_case else i % len(CONSTRAINT_SEEDS)
            if key not in reference:
                reference[key] = json_reference(args, work, mesh, tile_case, seed)
            got = [open(os.path.join(out, "m", f), "rb").read() if status == 0 else None for f in JSON_COMPARED]
            if got != reference[key]:
                outcome = "silent_misread" if status == 0 else outcome + "_on_neutral"
        counts[outcome] = counts.get(outcome, 0) + 1
        log.write(json.dumps({"family": "json", "file": "tile.json" if tile_case else "constraints", "mutation": kind,
                              "outcome": outcome, "status": status, "seconds": round(sec, 3), "max_rss_mb": round(rss / 2**20),
                              "error": err.strip().splitlines()[0][:200] if err.strip() else ""}) + "\n")
    return counts, len(CONSTRAINT_SEEDS) + 1


OUTCOMES = ["clean_error", "success", "crash", "hang", "silent_misread", "partial_output", "over_limits",
            "unclean_error", "unnamed_error", "broken_install"]


def summarize(paths):
    """A markdown table (one row per family) from campaign logs."""
    rows = {}
    for path in paths:
        for line in open(path):
            r = json.loads(line)
            fam = rows.setdefault(r["family"], {"n": 0, "max_s": 0.0})
            fam["n"] += 1
            fam[r["outcome"]] = fam.get(r["outcome"], 0) + 1
            fam["max_s"] = max(fam["max_s"], r.get("seconds", 0))
            fam["max_mb"] = max(fam.get("max_mb", 0), r.get("max_rss_mb", 0))
    print("| family | inputs | " + " | ".join(o.replace("_", " ") for o in OUTCOMES) + " | other | slowest run | largest run |")
    print("| --- " * (len(OUTCOMES) + 5) + "|")
    for fam, c in rows.items():
        other = c["n"] - sum(c.get(o, 0) for o in OUTCOMES)
        mb = ("%d MiB" % c["max_mb"]) if c.get("max_mb") else "n/a"
        print("| %s | %d | %s | %d | %.2f s | %s |" % (fam, c["n"], " | ".join(str(c.get(o, 0)) for o in OUTCOMES),
                                                      other, c["max_s"], mb))


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--summarize":
        summarize(sys.argv[2:])
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", required=True)
    ap.add_argument("--family", default="all", choices=["meshes", "images", "json", "all"])
    ap.add_argument("--count", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=21)
    ap.add_argument("--timeout", type=float, default=10.0,
                    help="wall seconds after which a run is killed and counted as a hang (default 10)")
    ap.add_argument("--clock", choices=["cpu", "wall"], default="cpu",
                    help="the 10 s limit of over_limits in CPU seconds of the run (default; fair on a loaded "
                         "machine) or wall seconds")
    ap.add_argument("--out", default="hostile_campaign.jsonl")
    ap.add_argument("--server", help="build/bench/hostile_fork_server: run each input in a forked child of one "
                                     "process instead of starting surftex each time (same code, no start-up cost)")
    args = ap.parse_args()
    global SERVER, CLOCK
    CLOCK = args.clock
    if args.server:
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1")  # no BLAS threads in the parent: safe to fork
        SERVER = subprocess.Popen(["nice", "-n", "10", args.server], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  text=True, env=env)
    families = ["meshes", "images", "json"] if args.family == "all" else [args.family]
    with open(args.out, "a") as log:
        for fam in families:
            rnd = random.Random(args.seed)
            work = tempfile.mkdtemp(prefix="surftex-campaign-")
            t0 = time.monotonic()
            fn = {"meshes": campaign_meshes, "images": campaign_images, "json": campaign_json}[fam]
            counts, nseeds = fn(args, rnd, work, log)
            shutil.rmtree(work, ignore_errors=True)
            print(json.dumps({"bench": "hostile_campaign", "family": fam, "inputs": args.count, "seeds": nseeds,
                              "seed": args.seed, "outcomes": counts, "seconds": round(time.monotonic() - t0, 1),
                              "load": os.getloadavg()[0]}), flush=True)


if __name__ == "__main__":
    main()
