#!/usr/bin/env bash
# ctest `installed_binary`: `cmake --install` into a temporary prefix, then the
# installed handlabel's synth + label (the shipped network, fitting as fallback) +
# merge from a folder outside the checkout, with the source and build trees out of
# reach: in a private mount namespace an empty read-only tmpfs covers each of them (as
# if renamed away), and strace records every path the binary touches, none of which
# may lie in either tree. The hand model and the network must come from the prefix.
# Usage: installed_binary_test.sh SOURCE_DIR BUILD_DIR [CMAKE]
set -euo pipefail
src=$(realpath "$1")
build=$(realpath "$2")
cmake=${3:-cmake}
fail() { echo "installed_binary_test: FAIL: $*" >&2; exit 1; }

tmp=$(mktemp -d /tmp/handlabel-install.XXXXXX)
trap '[ -n "${KEEP_TMP:-}" ] || rm -rf "$tmp"' EXIT
case "$tmp/" in "$src/"* | "$build/"*) fail "$tmp lies inside the trees it hides" ;; esac
prefix=$tmp/prefix
"$cmake" --install "$build" --prefix "$prefix" > "$tmp/install.log"
hl=$prefix/bin/handlabel
models=$prefix/share/handlabel/models
[ -x "$hl" ] || fail "no $hl after install"
for f in open_hand_right.npz open_hand_left.npz poem_small_dexycb.pt; do
  [ -f "$models/$f" ] || fail "no $models/$f after install"
done

run=$tmp/run
mkdir "$run"
cat > "$run/job.yaml" <<EOF
name: installed
seed: 7
hand_model: ""                  # the shipped open hand, found beside the binary
input: {format: native, path: capture, frames: all}
cameras: {source: capture}
network: {weights: "$models/poem_small_dexycb.pt", batch_size: 2, threads: 2}
refine: {mode: fallback}
evidence: {keypoints_2d: both, masks: files}
output: {dir: labels, meshes: [ply], overlays: false, evaluate: true}
EOF
cat > "$run/steps.sh" <<'EOF'
set -euo pipefail
"$HL" synth --out capture --preset dexycb --frames 2 --seed 7 --threads 2
"$HL" label --job job.yaml --quiet
"$HL" merge --job job.yaml > merge.txt
EOF

# Inside the namespace: cover the trees, check they look empty, run the steps.
cat > "$tmp/hidden.sh" <<'EOF'
set -euo pipefail
for dir in ${HIDE:+"$BUILD" "$SRC"}; do
  mount -t tmpfs -o ro,size=1k handlabel-hidden "$dir"
  [ -z "$(ls -A "$dir")" ] || { echo "could not hide $dir" >&2; exit 1; }
done
cd "$RUN"
unset OLDPWD  # bash would look at it on start
exec strace -f -qq --seccomp-bpf -e trace=%file -o "$TRACE" bash steps.sh
EOF
command -v strace > /dev/null || fail "strace is needed (scripts/install-deps installs it)"
trace=$tmp/trace.txt
# Mounting needs root (or a user namespace); without it strace alone has to show that
# nothing in the trees is touched.
namespace=(unshare --mount --propagation private)
hide=1
if ! unshare --mount --propagation private true 2> /dev/null; then
  if unshare --mount --map-root-user --propagation private true 2> /dev/null; then
    namespace=(unshare --mount --map-root-user --propagation private)
  else
    echo "installed_binary_test: no mount namespace here: trees not hidden, strace only"
    namespace=()
    hide=
  fi
fi
env -u HANDLABEL_SOURCE_DIR -u HANDLABEL_DATA_DIR -u HANDLABEL_HAND_MODEL \
  HOME="$run" HL="$hl" SRC="$src" BUILD="$build" RUN="$run" TRACE="$trace" HIDE="$hide" \
  "${namespace[@]}" bash "$tmp/hidden.sh" > "$tmp/run.log" 2>&1 ||
  { cat "$tmp/run.log" >&2; fail "synth + label + merge of the installed binary"; }

# Nothing under either tree was even looked at (a covered path would just be missing).
if grep -F -e "\"$src/" -e "\"$src\"" -e "\"$build/" -e "\"$build\"" "$trace" > "$tmp/leaks.txt"; then
  head -20 "$tmp/leaks.txt" >&2
  fail "the installed binary touched paths in the source or build tree"
fi
for frame in 000000 000001; do
  [ -f "$run/labels/labels/$frame.json" ] || fail "no label for frame $frame"
done
grep -q "\"source\": \"$models/open_hand_right.npz\"" "$run/capture/capture.json" ||
  fail "synth did not use $models/open_hand_right.npz (see $run/capture/capture.json)"
sha=$(sha256sum "$models/poem_small_dexycb.pt" | cut -d' ' -f1)
grep -q "\"weights_sha256\": \"$sha\"" "$run/labels/labels/000000.json" ||
  fail "the label does not record the installed network's sha256 $sha"
grep -q '"ok": 2' "$run/labels/manifest.json" || fail "not every frame labelled"
echo "installed_binary_test: $hl ran synth + label + merge from $run with" \
     "$src and $build ${hide:+hidden and }untouched ($(wc -l < "$trace") file calls traced)"
