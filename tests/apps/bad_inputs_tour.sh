#!/bin/bash
# A tour of the bad inputs and faults of issue 22's "Why" and of issue 46
# (docs/reliability.md) with a built binary, as a user meets them: each gives a
# non-zero exit (or a failed frame in an otherwise good run) whose message names the
# file, the field and what was expected, and loses nothing already written. Prints
# PASS/FAIL per check; exit 1 if any failed. The same cases have GoogleTest tests;
# this script checks a whole build (e.g. a release) in a few minutes.
# usage: tests/apps/bad_inputs_tour.sh BUILD/apps/handlabel SOURCE_DIR SCRATCH_DIR
H=$(realpath "$1"); SRC=$(realpath "$2")
mkdir -p "$3" && D=$(mktemp -d "$3/tour.XXXXXX") && cd "$D" || exit 2
echo "scratch: $D"
PY=/usr/bin/python3
pass=0; fail=0
report() { # name ok detail
  if [ "$2" = 1 ]; then pass=$((pass+1)); echo "PASS  $1"; else fail=$((fail+1)); echo "FAIL  $1  :: $3"; fi
}
# expect_fail NAME "substr1|substr2|..." cmd...   (non-zero exit, every substring in output)
expect_fail() {
  local name=$1 subs=$2; shift 2
  local out; out=$("$@" 2>&1); local rc=$?
  local ok=1 missing=""
  [ $rc -ne 0 ] || { ok=0; missing="exit 0;"; }
  IFS='|' read -ra parts <<< "$subs"
  for s in "${parts[@]}"; do grep -qF -- "$s" <<< "$out" || { ok=0; missing="$missing missing '$s';"; }; done
  report "$name" $ok "rc=$rc $missing out: $(tail -c 400 <<< "$out" | tr '\n' ' ')"
  LAST_OUT=$out
}
contains_all() { # text "a|b"
  local text=$1; IFS='|' read -ra parts <<< "$2"
  for s in "${parts[@]}"; do grep -qF -- "$s" <<< "$text" || return 1; done; return 0
}
json_edit() { $PY - "$@" <<'PYEOF'
import json, sys
path, code = sys.argv[1], sys.argv[2]
j = json.load(open(path))
exec(code)
open(path, "w").write(json.dumps(j))
PYEOF
}
manifest_reason() { $PY -c "
import json,sys
m=json.load(open('$1/manifest.json'))
for e in m['frames']:
    if e['frame']=='$2': print(e.get('status'), '::', e.get('reason',''))
"; }

nice -n 5 $H synth --preset dexycb --frames 4 --seed 9 --size 160x120 --hand-model capsule \
  --threads 1 --out cap > synth.log 2>&1 || { echo "synth failed"; exit 2; }
job() { # name capture out [extra output yaml]
  cat > $1.yaml <<Y
name: why
seed: 3
hand_model: capsule
input: {format: native, path: $2}
network: {threads: 1, batch_size: 2}
refine: {mode: always}
evidence: {keypoints_2d: files, masks: none}
output: {dir: $3, meshes: [ply], overlays: ${4:-false}}
Y
}

# --- rig files -------------------------------------------------------------------
rig_case() { # name python-edit "substrings"
  cp cap/rig.json rig_$1.json; json_edit rig_$1.json "$2"
  expect_fail "rig: $1" "rig_$1.json|$3" $H cameras show json:rig_$1.json
}
rig_case width_4294967936 "j['cameras'][0]['width']=4294967936" "width|[1, 65536]|4294967936"
rig_case width_2pow31 "j['cameras'][0]['width']=2**31" "width|[1, 65536]|2147483648"
rig_case height_2pow40 "j['cameras'][0]['height']=2**40" "height|1099511627776"
rig_case translation_1e308 "j['cameras'][0]['cam_from_world']['translation'][0]=1e308" "translation|10000"
rig_case unknown_key_focal "j['cameras'][0]['focal']=500" "focal|expected"
rig_case unknown_key_camera "j['camera']='cam00'" "camera|expected"
rig_case focal_1e300 "j['cameras'][0]['params'][0]=1e300" "focal length|expected"
rig_case cx_minus_1e6 "j['cameras'][0]['params'][2]=-1e6" "cx|expected"
# duplicate key: text edit
sed '0,/"height": 120/s//"height": 120, "height": 240/' cap/rig.json > rig_dupkey.json
expect_fail "rig: duplicate key" "rig_dupkey.json|height|once" $H cameras show json:rig_dupkey.json
# rig compare with a camera only in the second rig
cp cap/rig.json rig_a.json; cp cap/rig.json rig_b.json
json_edit rig_b.json "j['cameras'][1]['name']='extra'"
expect_fail "cameras compare: camera only in the second rig" \
  "json:rig_a.json: field 'camera 'extra''|expected the same camera names|only in json:rig_b.json" \
  $H cameras compare json:rig_a.json json:rig_b.json

# --- detections, images in a labeling job ----------------------------------------
cp -r cap cap_bad
json_edit cap_bad/detections/000000.json "
for v in j['views']: v['confidence']=[0.0]*21"
json_edit cap_bad/detections/000001.json "j['views'][2]['confidence'][4]=7.5"
json_edit cap_bad/detections/000003.json "
for v in j['views']: v['confidence']=[-3.0]*21"
img=$(ls cap_bad/images/*/000002.png | head -1); echo "not a picture" > $img
job bad cap_bad out_bad true
out=$($H label --job bad.yaml 2>&1); rc=$?
r0=$(manifest_reason out_bad 000000); r1=$(manifest_reason out_bad 000001)
r2=$(manifest_reason out_bad 000002); r3=$(manifest_reason out_bad 000003)
contains_all "$r0" "failed|detections/000000.json|confidence|expected" ; report "detections all confidence 0 -> frame fails by name" $((1-$?)) "$r0"
contains_all "$r1" "failed|detections/000001.json|views[2].confidence[4]|[0, 1]|7.5" ; report "confidence 7.5 -> frame fails by name" $((1-$?)) "$r1"
contains_all "$r2" "failed|$img" ; report "broken image, fit-only job with overlays -> frame fails naming the image" $((1-$?)) "$r2"
contains_all "$r3" "failed|detections/000003.json|confidence|[0, 1]" ; report "confidence -3 -> frame fails by name" $((1-$?)) "$r3"
grep -qE "4 failed" <<< "$out"; report "label summary counts 4 failed" $((1-$?)) "$(tail -n2 <<< "$out"|tr '\n' ' ')"

# image / mask size mismatch (fit with masks)
cp -r cap cap_mask
m=$(ls cap_mask/masks/cam03/000001.png); $PY -c "
from PIL import Image; Image.new('L',(80,60)).save('$m')"
$H fit --capture cap_mask --out fit_mask --masks truth --hand-model capsule --frames 000001 > fit_mask.log 2>&1
r=$(manifest_reason fit_mask 000001)
contains_all "$r" "failed|$m|160x120 (camera cam03)|80x60"; report "mask of another size -> frame fails naming file, camera, sizes" $((1-$?)) "$r"
cp -r cap cap_img
i=$(ls cap_img/images/cam05/000001.png); $PY -c "
from PIL import Image; Image.new('RGB',(80,60)).save('$i')"
job img cap_img out_img true
$H label --job img.yaml > img.log 2>&1
r=$(manifest_reason out_img 000001)
contains_all "$r" "failed|cam05|160x120|80x60"; report "image of another size (overlay) -> frame fails naming camera, sizes" $((1-$?)) "$r"
contains_all "$r" "$i"; report "image of another size (overlay) -> names the image file" $((1-$?)) "$r"

# --- output folder: truncation, resume, merge -------------------------------------
job good cap out_good
$H label --job good.yaml > good.log 2>&1 || echo "good label failed"
lab=$(ls out_good/labels/000001* | head -1); full=$(sha256sum < $lab)
sz=$(stat -c %s $lab); truncate -s $((sz/3)) $lab
expect_fail "merge after a label file was truncated" "000001|truncated" $H merge --job good.yaml
$H label --job good.yaml --resume > resume.log 2>&1
[ "$(sha256sum < $lab)" = "$full" ]; report "--resume relabels the truncated frame identically" $((1-$?)) "differs"
$H merge --job good.yaml > merge_ok.log 2>&1; report "merge passes after the resume" $((1-$?)) "$(cat merge_ok.log)"
man=$(sha256sum < out_good/manifest.json)
sed 's/seed: 3/seed: 4/' good.yaml > other.yaml
expect_fail "merge with another job's file" "job.json|another job" $H merge --job other.yaml
[ "$(sha256sum < out_good/manifest.json)" = "$man" ]; report "  ... manifest unchanged" $((1-$?)) "manifest changed"

# merge with a frame no shard ran names it
job shard cap out_shard
$H label --job shard.yaml --shard 0/2 > shard.log 2>&1
expect_fail "merge with frames not yet run names them" "000002 (not yet run)|000003 (not yet run)" $H merge --job shard.yaml

# frame listed twice
job twice cap out_twice; sed -i 's/path: cap}/path: cap, frames: "000000,000001,000000"}/' twice.yaml
expect_fail "frame listed twice in input.frames" "input.frames|once|000000" $H label --job twice.yaml
[ ! -e out_twice/labels ] || [ -z "$(ls out_twice/labels)" ]; report "  ... nothing labelled" $((1-$?)) "labels written"
# duplicate YAML key
job dup cap out_dup; sed -i 's/^seed: 3/seed: 3\nseed: 5/' dup.yaml
expect_fail "duplicate YAML key" "dup.yaml|seed|once" $H label --job dup.yaml

# --- output folder: two writers, stale lock ---------------------------------------
nice -n 5 $H synth --preset dexycb --frames 40 --seed 8 --size 160x120 --hand-model capsule --threads 1 --out cap40 > synth40.log 2>&1
job a cap40 out_ab; job b cap40 out_ab; sed -i 's/seed: 3/seed: 4/' b.yaml
$H label --job a.yaml > a.log 2>&1 &
apid=$!
for k in $(seq 600); do grep -q "pid $apid " out_ab/shards/shard-00000-of-00001.lock 2>/dev/null && break; sleep 0.01; done
kill -STOP $apid
expect_fail "second job with --force while a run holds the folder" "pid $apid|host" $H label --job b.yaml --force
expect_fail "same job started twice at once" "pid $apid|host" $H label --job a.yaml
expect_fail "merge while a run holds the folder" "pid $apid" $H merge --job a.yaml
kill -CONT $apid; wait $apid; report "  ... the first run finishes" $((1-$?)) "$(tail -n2 a.log)"
$H merge --job a.yaml > ab_merge.log 2>&1; report "  ... merge passes" $((1-$?)) "$(cat ab_merge.log)"
recs=$(cat out_ab/shards/*.jsonl 2>/dev/null | wc -l); [ "$recs" = 40 ]; report "  ... one log record per frame (40)" $((1-$?)) "$recs records"
# stale lock after kill -9
job k cap40 out_k
$H label --job k.yaml > k.log 2>&1 &
kpid=$!
for k in $(seq 600); do grep -q "pid $kpid " out_k/shards/shard-00000-of-00001.lock 2>/dev/null && break; sleep 0.01; done
kill -9 $kpid; wait $kpid 2>/dev/null
$H label --job k.yaml --resume > k2.log 2>&1; report "stale lock after kill -9 does not block --resume" $((1-$?)) "$(tail -n2 k2.log)"

# --- fit --init, models ------------------------------------------------------------
mkdir -p init; $PY -c "
import json
p={'global_orient':[0,0,0],'hand_pose':[0.0]*45,'betas':[0.0]*10,'transl':[0,0,0.5]}
p['hand_pose'][7]=1e300
json.dump(p,open('init/000000.json','w'))"
expect_fail "fit --init with 1e300" "init/000000.json|hand_pose[7]|expected" \
  $H fit --capture cap --out fit_init --init init --frames 000000 --hand-model capsule
$H model convert $SRC/tests/data/mano/mano_py2_right.pkl right.npz --tips 1,7,5,8,6 > conv1.log 2>&1
$H model convert right.npz left.npz --side left > conv2.log 2>&1; rc=$?
info=$($H model info left.npz 2>&1)
[ $rc = 0 ] && grep -qi "left" <<< "$info"; report "model convert --side left of a right-hand file gives a left hand" $((1-$?)) "rc=$rc $(grep -i side <<< "$info")"
$H model convert right.npz tips.npz --tips 5,7,1,8,6 > conv3.log 2>&1
cmp -s right.npz tips.npz; report "model convert --tips applied to a file recording tips" $? "identical output"
expect_fail "model convert --tips outside the mesh" "--tips" $H model convert right.npz bad.npz --tips 1,7,5,8,999999
: > empty.npz
expect_fail "empty model file" "empty.npz|empty file" $H model info empty.npz

# --- checkpoint, training ----------------------------------------------------------
$PY - $SRC/models/poem_small_dexycb.pt short.pt <<'PYEOF'
import sys, zipfile
src, dst = sys.argv[1], sys.argv[2]
with zipfile.ZipFile(src) as zi, zipfile.ZipFile(dst, "w", zipfile.ZIP_STORED) as zo:
    for info in zi.infolist():
        data = zi.read(info)
        if info.filename.endswith("/data/0"): data = data[:4]
        zo.writestr(info.filename, data)
PYEOF
expect_fail "checkpoint storage shorter than its shape" "short.pt|storage|expected" \
  $H eval-network --weights short.pt --frames 1
sed 's/batch_size: 4/batch_size: -3/' $SRC/jobs/train_poem_small.yaml > train_neg.yaml
expect_fail "train.batch_size -3" "train.batch_size|expected" $H train --config train_neg.yaml --out run_neg --steps 1
grep -q reuse_group <<< "$LAST_OUT"; report "  ... no internal 'reuse_group'" $? "$LAST_OUT"
mkdir -p run_corrupt; echo '{"step": 12, "model": ' > run_corrupt/latest.json
expect_fail "corrupt latest.json" "run_corrupt/latest.json|expected" \
  $H train --config $SRC/jobs/train_poem_small.yaml --out run_corrupt --resume --steps 1
grep -q "error: run_corrupt/latest.json: field" <<< "$LAST_OUT"; report "  ... an InputError (file: field), not a raw JSON exception" $((1-$?)) "$LAST_OUT"

# --- calibration board -------------------------------------------------------------
expect_fail "board 100000x100000" "100000x100000|2 to 1000" \
  $H calib render-board --board charuco:100000x100000:0.03:0.022 --out board_out --frames 1 --near-frames 0

# --- issue 46: damaged input, names, messages --------------------------------------
cp -r cap cap46
json_edit cap46/detections/000000.json "j['views'][1]['keypoints'][5]=[1e308, 40]"
cp cap46/detections/000002.json cap46/detections/000001.json
job j46 cap46 out46
$H label --job j46.yaml > j46.log 2>&1
r0=$(manifest_reason out46 000000); r1=$(manifest_reason out46 000001)
contains_all "$r0" "failed|views[1].keypoints[5]|x in [-160, 320]"; report "detection keypoint at 1e308 fails its frame naming the range" $((1-$?)) "$r0"
contains_all "$r1" "failed|field 'frame'|'000001'"; report "detections file of another frame fails its frame" $((1-$?)) "$r1"
mkdir -p rec46/cam00 rec46/cam01
for i in 0 1 2; do for c in cam00 cam01; do
  ffmpeg -loglevel error -y -f lavfi -i "testsrc=size=160x120:rate=1" -frames:v 1 rec46/$c/f$i.jpg; done; done
head -c 1500 rec46/cam01/f1.jpg > cut.jpg && mv cut.jpg rec46/cam01/f1.jpg
$PY -c "
import json
j=json.load(open('cap/rig.json')); j['cameras']=j['cameras'][:2]
for c, n in zip(j['cameras'], ['cam00', 'cam01']): c['name']=n
json.dump(j, open('rig46.json', 'w'))"
$H capture init --rig json:rig46.json --out session46 > init46.log 2>&1
expect_fail "capture import of a truncated JPEG" "rec46/cam01/f1.jpg|expected a valid JPEG"   $H capture import --capture session46 --images rec46
sed 's/"cam01"/"cam 01"/' rig46.json > rig46_space.json
expect_fail "camera name with a space" "cameras[1] name|COLMAP|\"cam 01\"" \
  $H capture init --rig json:rig46_space.json --out session46_space
expect_fail "huge --offset says the range" "--offset|[-1000000000, 1000000000]" \
  $H capture import --capture session46 --videos rec46 --offset cam01=99999999999
expect_fail "huge --shard says the range" "N <= 999999999" $H label --job j46.yaml --shard 1/99999999999
head -c 3000 $SRC/models/poem_small_dexycb.pt > cut.pt
out=$($H eval-network --weights cut.pt --frames 1 2>&1); rc=$?
[ $rc = 1 ] && [ "$(wc -l <<< "$out")" = 1 ] && grep -qF cut.pt <<< "$out"; report "damaged --weights: one line naming the file" $((1-$?)) "rc=$rc $out"

# --- issue 46: one view of 2D, one writer per folder, stale evidence, training -----
first_camera() { $PY -c "import json; print(json.load(open('$1/capture.json'))['cameras'][0])"; }
# wait_holding PID FOLDER: until PID has recorded itself in FOLDER's lock
wait_holding() { for k in $(seq 1500); do grep -q "pid $1 " $2/.handlabel.lock 2>/dev/null && return 0; sleep 0.01; done; return 1; }
cp -r cap cap1v
json_edit cap1v/detections/000001.json "
for v in j['views'][1:]: v['confidence']=[0.0]*21"
job one cap1v out1v
$H label --job one.yaml > one.log 2>&1; rc=$?
r=$(manifest_reason out1v 000001)
contains_all "$r" "failed|2D keypoints in only 1 view ($(first_camera cap))|depth is not determined"
report "2D keypoints in one view only -> frame fails by name" $((1-$?)) "rc=$rc $r"
oks=$(for f in 000000 000002 000003; do manifest_reason out1v $f; done | grep -c "^ok ")
[ $rc = 0 ] && [ "$oks" = 3 ]; report "  ... the other frames are labelled" $((1-$?)) "rc=$rc ok=$oks"
$H label --job one.yaml --resume > one2.log 2>&1; report "  ... --resume finishes" $((1-$?)) "$(tail -n2 one2.log)"

# capture import: one writer; the first completes
mkdir -p rec40 && cp -r cap40/images/. rec40/
$H capture init --rig json:cap40/rig.json --out imp > imp_init.log 2>&1
$H capture import --capture imp --images rec40 --threads 1 > imp.log 2>&1 &
ipid=$!
wait_holding $ipid imp; kill -STOP $ipid
expect_fail "capture import --overwrite while an import runs" \
  "no other process is writing|in use by capture import, pid $ipid" \
  $H capture import --capture imp --images rec40 --overwrite
expect_fail "detect --capture while an import runs" "in use by capture import, pid $ipid" \
  $H detect --capture imp
kill -CONT $ipid; wait $ipid; report "  ... the first import finishes" $((1-$?)) "$(tail -n2 imp.log)"
st=$($PY -c "import json; j=json.load(open('imp/capture.json')); print(j['generator'].get('import_status'), len(j['frames']))")
n=$(ls imp/images/*/*.png | wc -l)
[ "$st" = "complete 40" ] && [ "$n" = $((40 * $(ls rec40 | wc -l))) ]
report "  ... complete, 40 frames, every view on disk" $((1-$?)) "$st, $n images"
# two detects (full, then lite) on one capture
cp -r cap40 cap40d
$H detect --capture cap40d --overwrite --threads 1 > det1.log 2>&1 &
dpid=$!
wait_holding $dpid cap40d; kill -STOP $dpid
expect_fail "detect --capture while a detect runs" "in use by detect --capture, pid $dpid" \
  $H detect --capture cap40d --overwrite --model lite
kill -CONT $dpid; wait $dpid; report "  ... the first detect finishes" $((1-$?)) "$(tail -n2 det1.log)"

# a re-import with --overwrite: the old recording's 2D, masks and truth are unlisted
cp -r cap cap_re; mkdir -p rec4 && cp -r cap/images/. rec4/
out=$($H capture import --capture cap_re --images rec4 --overwrite 2>&1); rc=$?
files=$($PY -c "import json; print(sorted(json.load(open('cap_re/capture.json'))['files']))")
[ $rc = 0 ] && [ "$files" = "['image']" ] && contains_all "$out" "no longer lists|detections (detections/{frame}.json)|keypoints|mask|ground_truth"
report "capture import --overwrite unlists the old detections, keypoints, masks, truth" $((1-$?)) "rc=$rc $files $out"

# training: one writer, resume with other data, damaged optimizer state, sizes, full disk
train_yaml() { # file out_dir seed batch
  printf '%s\n' "network: tiny" 'hand_model: ""' \
    "data: {preset: dexycb, width: 320, height: 240, seed: $3}" "train:" "  steps: 4" \
    "  batch_size: $4" "  warmup_steps: 1" "  checkpoint_every: 1" "  log_every: 1" \
    "  validate_every: 4" "  validation_samples: 1" "  prefetch_batches: 0" \
    "  out_dir: $2" > $1
}
train_yaml tr.yaml run46 4 1
$H train --config tr.yaml > tr.log 2>&1 &
tpid=$!
wait_holding $tpid run46; kill -STOP $tpid
expect_fail "train --resume while a training runs on the folder" "in use by train, pid $tpid" \
  $H train --config tr.yaml --resume
kill -CONT $tpid; wait $tpid; report "  ... the first training finishes" $((1-$?)) "$(tail -n2 tr.log)"
steps=$(tail -n +2 run46/loss.csv | cut -d, -f1 | tr '\n' ' ')
[ "$steps" = "1 2 3 4 " ]; report "  ... loss.csv has each step once" $((1-$?)) "$steps"
train_yaml tr5.yaml run46 5 1
expect_fail "train --resume with another data seed" "latest.json: field 'data.synth.seed'|got 5" \
  $H train --config tr5.yaml --resume --steps 5
optim=$(ls run46/checkpoints/*.optim | tail -n1); truncate -s 100 $optim
expect_fail "train --resume with a truncated .optim" "$optim" $H train --config tr.yaml --resume --steps 5
[ "$(grep -c "error" <<< "$LAST_OUT")" = 1 ] && ! grep -qE "Exception raised from|frame #" <<< "$LAST_OUT"
report "  ... one error line, no backtrace" $((1-$?)) "$LAST_OUT"
train_yaml trbig.yaml runbig 4 1000000000
expect_fail "train.batch_size 1000000000" "train.batch_size|fit in memory" $H train --config trbig.yaml
train_yaml trfull.yaml runfull 4 1
out=$( (trap '' XFSZ; ulimit -f 16; exec $H train --config trfull.yaml) 2>&1); rc=$?
grep -qF "cannot write 'runfull/checkpoints/step_00000001.pt'" <<< "$out" && [ $rc = 1 ] \
  && [ -z "$(find runfull -name '*.tmp*')" ] && [ ! -e runfull/latest.json ]
report "a full disk while a checkpoint is written: one line naming the file, no .tmp" $((1-$?)) "rc=$rc $(tail -c 300 <<< "$out")"

echo "---- $pass passed, $fail failed"
[ $fail = 0 ]
