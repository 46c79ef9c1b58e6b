#!/usr/bin/env bash
# Byte-identity check for pure refactors (issue 22): runs the same commands
# (every method, its CLI variants, the mesh readers and writers), fixed seeds
# and --threads 2, with a reference binary and a new binary, and compares
# every output file by sha256 (report.json with its timing, version and
# command-line keys stripped; stdout, stderr and the exit code too).
# Usage: scripts/refactor_check.sh REF_SURFTEX NEW_SURFTEX [WORK_DIR]
# The reference: surftex built at the commit before the refactor, with
# libsurftex_image_io.so copied beside it (the image IO module is looked up
# there). ONLY=REGEX (environment) keeps only the runs whose name matches
# (a run reading an earlier one's output, as quilt_.* the swatch's, needs
# that one in the regex too). Exit 0 when every file matches.
set -uo pipefail
ref="$(readlink -f "$1")"
new="$(readlink -f "$2")"
work="${3:-/tmp/refactor-check}"
D=/work/shared/data
rm -rf "$work"
mkdir -p "$work/in" "$work/ref" "$work/new"
C=(--seed 7 --threads 2 -q)

# Inputs both sides share: material constraints, PLY variants of one mesh.
cat >"$work/in/c1.json" <<'EOF'
{"strokes": [{"polyline": [[0.2, 0, 0.3], [0, 0.1, 0], [-0.2, 0, -0.3]]}],
 "material": [{"point": [0, 0, 0.45], "value": 1}, {"point": [0, 0, -0.45], "value": 0}]}
EOF
cat >"$work/in/c2.json" <<'EOF'
{"effect_radius": 0.15,
 "strokes": [{"faces": [10], "direction": [0, 0, 1]}],
 "scale": [{"point": [0.2, 0, 0], "value": 0.4}], "material": [{"point": [0.2, 0, 0], "value": 0.2}]}
EOF
python3 - "$D/meshes/eight_genus2.off" "$work/in" <<'EOF'
import struct, sys
src, out = sys.argv[1], sys.argv[2]
tok = open(src).read().split()
nv, nf = int(tok[1]), int(tok[2])
pts = [tuple(float(x) for x in tok[4 + 3 * i: 7 + 3 * i]) for i in range(nv)]
p, faces = 4 + 3 * nv, []
for _ in range(nf):
    k = int(tok[p]); faces.append([int(x) for x in tok[p + 1: p + 1 + k]]); p += 1 + k
def header(fmt, vt, it, extra_v="", extra_f=""):
    return ("ply\nformat %s 1.0\ncomment made by refactor_check\nelement vertex %d\nproperty %s x\nproperty %s y\n"
            "property %s z\n%selement face %d\nproperty list uchar %s vertex_indices\n%send_header\n"
            % (fmt, nv, vt, vt, vt, extra_v, nf, it, extra_f)).encode()
with open(out + "/ascii.ply", "wb") as f:
    f.write(header("ascii", "float", "int", "property uchar red\n"))
    for i, q in enumerate(pts): f.write(("%g %g %g %d\n" % (q + (i % 256,))).encode())
    for fc in faces: f.write((" ".join(map(str, [len(fc)] + fc)) + "\n").encode())
with open(out + "/bin_le_double.ply", "wb") as f:
    f.write(header("binary_little_endian", "double", "uint", "", "property float quality\n"))
    for q in pts: f.write(struct.pack("<3d", *q))
    for fc in faces: f.write(struct.pack("<B%dIf" % len(fc), len(fc), *fc, 0.5))
with open(out + "/bin_be.ply", "wb") as f:
    f.write(header("binary_big_endian", "float", "int"))
    for q in pts: f.write(struct.pack(">3f", *q))
    for fc in faces: f.write(struct.pack(">B%di" % len(fc), len(fc), *fc))
with open(out + "/truncated.ply", "wb") as f:
    data = open(out + "/bin_be.ply", "rb").read()
    f.write(data[: len(data) - 37])
EOF

# run NAME ARGS...: @O in an argument is the side's output folder, @I the shared inputs.
run() {
  local name="$1"; shift
  [[ -n ${ONLY:-} && ! $name =~ $ONLY ]] && return 0
  for side in ref new; do
    local bin="$ref"; [[ $side == new ]] && bin="$new"
    local o="$work/$side" args=() a
    local prev=""
    for a in "$@"; do
      a="${a//@O/$o}"; a="${a//@I/$work/in}"
      # an output file's folder must exist
      if [[ $prev == -o && "$(basename "$a")" == *.* ]]; then mkdir -p "$(dirname "$a")"; fi
      args+=("$a"); prev="$a"
    done
    mkdir -p "$o/_log"
    local t0=$SECONDS
    (cd "$o" && "$bin" "${args[@]}" >"$o/_log/$name.out" 2>"$o/_log/$name.err"; echo $? >"$o/_log/$name.rc")
    echo "$side $name $((SECONDS - t0))" >>"$work/times.txt"
    # paths as placeholders; timing lines ("read time: 0.015 s") dropped
    sed -i "s#$o#@O#g; s#$work/in#@I#g; /time: *[0-9.]* s\$/d" "$o/_log/$name.out" "$o/_log/$name.err"
  done
}

# Ray 2009: material tile (mask morph), then the mapping (PGP solve, singularities).
run tile material-tile "$D/textures/brick_small_96.png" "$D/textures/leather_64.png" -o @O/tile --size 64 --layers 2 "${C[@]}"
run mm material-map "$D/meshes/eight_genus2.off" --tile @O/tile --constraints @I/c1.json -o @O/mm \
  --render-size 64 --atlas-size 128 "${C[@]}"
run mm_up material-map "$D/meshes/eight_genus2.off" --tile @O/tile --update @I/c2.json --state @O/mm/state.json \
  -o @O/mm_up --render-size 64 --atlas-size 128 "${C[@]}"
run mm_noswap material-map "$D/meshes/eight_genus2.off" --tile @O/tile --constraints @I/c1.json --no-swap -o @O/mm_noswap \
  --render-size 64 --atlas-size 128 "${C[@]}"
run mm_noswap_up material-map "$D/meshes/eight_genus2.off" --tile @O/tile --update @I/c2.json \
  --state @O/mm_noswap/state.json -o @O/mm_noswap_up --render-size 64 --atlas-size 128 "${C[@]}"
run mm_curl material-map "$D/meshes/fish_blub.obj" --tile @O/tile --curl-correction --field constant -o @O/mm_curl \
  --render-size 64 --atlas-size 128 "${C[@]}"
# Gorla 2003: direction field, partition, graph-cut fill.
run patches patches "$D/meshes/fish_blub.obj" "$D/textures/brick_small_96.png" -o @O/patches --patch-res 24 \
  --max-patch-faces 40 --window 7 --rotations 16 --resynth 0,2 --field kmax "${C[@]}"
run patches_up patches "$D/meshes/eight_genus2.off" "$D/textures/leather_64.png" -o @O/patches_up --patch-res 24 \
  --max-patch-faces 60 --window 7 --rotations 8 --field up "${C[@]}"
# Zhou 2006: quilting on a plane and on a surface (shell space, embedding, stretch, merging).
run swatch swatch scatter -o @O/sw.obj "${C[@]}"
run swatch_tori swatch tori -o @O/tori.obj --size 2 "${C[@]}"
run quilt_plane quilt --plane 1.6x1.6 @O/sw.obj -o @O/qp/p.ply --report @O/qp/report.json "${C[@]}"
run quilt_chain quilt --plane 1.5x1.5 chainmail -o @O/qc/c.ply --report @O/qc/report.json --no-render "${C[@]}"
run quilt_tori quilt "$D/meshes/fish_blub.obj" @O/tori.obj -o @O/qt/q.ply --stretch-iterations 2 --no-render \
  --report @O/qt/report.json "${C[@]}"
# Bangay 2006: sqrt(2) subdivision.
run subdiv subdiv "$D/meshes/spot_quads.obj" "$D/textures/brick_small_96.png" -o @O/sd --levels 3 --atlas-size 64 "${C[@]}"
run subdiv_adapt subdiv "$D/meshes/eight_genus2.off" "$D/textures/leather_64.png" -o @O/sd2 --levels 2 --adaptive 1.5 \
  --atlas-size 64 "${C[@]}"
# Grey maps of the exemplars' sizes (PGM) for the height/roughness inputs.
python3 - "$work/in" <<'EOF2'
import sys
for n in (64, 96):
    for name, f in (("h", lambda x, y: (x * 7 + y * 3) % 256), ("r", lambda x, y: 64 + (x ^ y) % 128)):
        with open("%s/%s%d.pgm" % (sys.argv[1], name, n), "wb") as o:
            o.write(b"P5 %d %d 255\n" % (n, n) + bytes(f(x, y) for y in range(n) for x in range(n)))
EOF2
# Gorla 2003 variants: principal-direction fields, curvature order, direction fill,
# multi-texturing, exhaustive and approximate search, exemplar maps.
run patches_multi patches "$D/meshes/fish_blub.obj" "$D/textures/brick_small_96.png" -o @O/pm --patch-res 24 \
  --max-patch-faces 40 --window 7 --rotations 8 --field kmax-abs --order curvature --fill direction --search exhaustive \
  --exemplar2 "$D/textures/burlap_96.png" --multi curvature "${C[@]}"
run patches_maps patches "$D/meshes/spot_quads.obj" "$D/textures/brick_small_96.png" -o @O/pmaps --patch-res 24 \
  --max-patch-faces 60 --window 5 --field kmin-abs --exemplar-roughness @I/r96.pgm --exemplar-height @I/h96.pgm "${C[@]}"
run patches_illum patches "$D/meshes/eight_genus2.off" "$D/textures/leather_64.png" -o @O/pi --patch-res 24 \
  --max-patch-faces 60 --window 5 --field none --exemplar2 "$D/textures/coffee_beans_64.png" --multi illumination \
  --search approximate "${C[@]}"
run patches_height patches "$D/meshes/spot_quads.obj" "$D/textures/leather_64.png" -o @O/ph --patch-res 24 \
  --max-patch-faces 60 --window 5 --field kmin --exemplar2 "$D/textures/coffee_beans_64.png" --multi height \
  --rotations 4 --resynth 1 "${C[@]}"
# Efros-Leung in 2D (onion peel from the centre seed, rotations, both searches) and graph-cut synthesis.
run synth_el synth "$D/textures/brick_small_96.png" -o @O/synth/el.png --size 40x40 --window 7 "${C[@]}"
run synth_el_rot synth "$D/textures/leather_64.png" -o @O/synth/rot.png --size 32x32 --window 5 --angle 0.6 \
  --rotations 8 --search exhaustive "${C[@]}"
run synth_el_ann synth "$D/textures/leather_64.png" -o @O/synth/ann.png --size 32x32 --window 5 --search approximate \
  --periodic "${C[@]}"
run synth_gc synth "$D/textures/brick_small_96.png" -o @O/synth/gc.png --size 128x128 --method graphcut "${C[@]}"
# Periodic tiles with the straight-seam repair.
run tile_seams tile "$D/textures/brick_small_96.png" -o @O/tb/b.png --size 64 --straight-seam-steps 12 \
  --preview @O/tb/b2.png --report @O/tb/report.json "${C[@]}"
run tile_seams2 tile "$D/textures/cane_weave_rgba_128.png" -o @O/tm/m.png --size 64 --synthesis-cut --report @O/tm/report.json "${C[@]}"
# Bangay 2006 variants: repetition penalty and coherent matching, exemplar maps, pyramid, no cut, bounded.
run subdiv_maps subdiv "$D/meshes/spot_quads.obj" "$D/textures/brick_small_96.png" -o @O/sdm --levels 2 --atlas-size 64 \
  --repetition-penalty 0.5 --exhaustive-levels 1 --exemplar-height @I/h96.pgm --exemplar-roughness @I/r96.pgm "${C[@]}"
run subdiv_pyr subdiv "$D/meshes/eight_genus2.off" "$D/textures/leather_64.png" -o @O/sdp --levels 2 --atlas-size 64 \
  --pyramid --no-cut --no-averaging --wrap periodic "${C[@]}"
run subdiv_bounded subdiv "$D/meshes/eight_genus2.off" "$D/textures/leather_64.png" -o @O/sdb --levels 1 --atlas-size 64 \
  --wrap bounded --no-antialias --projection --passes 2 "${C[@]}"
# Zhou 2006 CLI variants: GLB and OBJ outputs, no field, no check.
run quilt_plane_glb quilt --plane 1.2x1.2 weave -o @O/qg/w.glb --scale 0.5 --no-render --report @O/qg/report.json "${C[@]}"
run quilt_none quilt "$D/meshes/fish_blub.obj" @O/tori.obj -o @O/qn/q.obj --field none --no-check --stretch-iterations 1 \
  --report @O/qn/report.json "${C[@]}"
# glTF writer: materials with a texture, and an attached texture.
run convert_glb_chair convert "$D/meshes/chair.obj" -o @O/glb1/c.glb "${C[@]}"
run convert_glb_tex convert "$D/meshes/spot_quads.obj" -o @O/glb2/s.glb --texture "$D/textures/leather_64.png" "${C[@]}"
# Readers: OFF, OBJ, PLY (ascii, binary both endians), STL, broken files.
i=0
for m in "$D"/meshes/{eight_genus2.off,double_torus_polygons.off,spot_quads.obj,fish_blub.obj,spot.ply,cow.off,coffee_cup.obj} \
         "$D"/broken/* "$work"/in/*.ply; do
  i=$((i + 1))
  b="$(basename "$m")"
  run "info_$i" info "$m"
  run "info_nt_$i" info "$m" --no-triangulate
  run "repair_$i" repair "$m" -o "@O/rep_$i/$b.off" --fill-holes "${C[@]}"
  run "convert_$i" convert "$m" -o "@O/conv_$i/m.ply" "${C[@]}"
  run "convert_obj_$i" convert "$m" -o "@O/conv_obj_$i/m.obj" --no-triangulate "${C[@]}"
done

# Compare: every file by sha256; report.json without its timing, version and command-line keys.
python3 - "$work" <<'EOF'
import hashlib, json, os, re, sys
work = sys.argv[1]
DROP = ("seconds", "time", "version", "command", "argv", "elapsed", "date", "host", "threads_used", "peak", "share", "per_second")
def strip(j):
    if isinstance(j, dict):
        return {k: strip(v) for k, v in j.items() if not any(d in k.lower() for d in DROP)}
    if isinstance(j, list):
        return [strip(v) for v in j]
    return j
def digest(path, side):
    data = open(path, "rb").read()
    if os.path.basename(path) == "report.json":
        # timings, version, command line dropped; the side's folder as a placeholder;
        # input hashes dropped (the inputs themselves are compared as files)
        data = data.replace(os.path.join(work, side).encode(), b"@O")
        j = strip(json.loads(data))
        for i in j.get("inputs", []) if isinstance(j, dict) else []:
            if isinstance(i, dict): i.pop("sha256", None)
        data = json.dumps(j, sort_keys=True).encode()
    elif path.endswith((".tif", ".tiff")):
        data = re.sub(rb"\d{4}:\d\d:\d\d \d\d:\d\d:\d\d", b"DATETIME", data)  # TIFF DateTime tag
    return hashlib.sha256(data).hexdigest()
def tree(side):
    root, out = os.path.join(work, side), {}
    for d, _, fs in os.walk(root):
        for f in fs:
            p = os.path.join(d, f)
            out[os.path.relpath(p, root)] = digest(p, side)
    return out
a, b = tree("ref"), tree("new")
bad = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
for k in bad:
    print("DIFF", k, a.get(k, "-")[:12], b.get(k, "-")[:12])
nonzero = sum(1 for k in a if k.endswith(".rc") and open(os.path.join(work, "ref", k)).read().strip() != "0")
print(f"files compared: {len(set(a) | set(b))}, different: {len(bad)} (runs with nonzero exit: {nonzero})")
sys.exit(1 if bad else 0)
EOF
