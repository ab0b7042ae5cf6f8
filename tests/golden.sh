#!/usr/bin/env bash
# golden.sh: the emitted code of every model and scene (models/, tests/models/,
# tests/extremes/models/), in double and in float, and the flexible
# slider-crank's LDL^T as loops (MBCC_LDL_BUDGET=0), hashed file by file
# against tests/golden/emitted.sha256.  A restructuring leaves this manifest
# unchanged; an intended change of the emitted code updates it in a commit of
# its own that names the change.
#   bash tests/golden.sh            check (exit 1 and the differing files)
#   bash tests/golden.sh --update   rewrite the manifest
#   bash tests/golden.sh --out DIR  also keep the emitted trees in DIR (for a
#                                   diff between two builds: scripts/golden-diff.sh)
# Models are named relative to the repository, so the paths the generated
# code quotes are the same on every machine.  Environment: MBCC (default build/mbcc).
set -u
cd "$(dirname "$0")/.." || exit 1
MBCC=${MBCC:-build/mbcc}
case $MBCC in /*) ;; *) MBCC="$(pwd)/$MBCC" ;; esac
[ -x "$MBCC" ] || { echo "golden: no mbcc at $MBCC"; exit 1; }
manifest=tests/golden/emitted.sha256
mode=check out=
while [ $# -gt 0 ]; do
  case $1 in
    --update) mode=update ;;
    --out) out=$2; shift ;;
    *) echo "golden: unknown argument '$1'"; exit 2 ;;
  esac
  shift
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
[ -n "$out" ] || out=$tmp/emitted
mkdir -p "$out"

scenes_of() {
  awk '/^scenes:/ { s = 1; next } s && /^[^ #]/ { s = 0 } s && /^  [a-z0-9_]+:/ { sub(/:.*/, ""); print $1 }' "$1"
}

# emit NAME MODEL SCENE [extra mbcc args...]: compile into $out/NAME
fail=0 n=0
emit() {
  local name=$1 model=$2 scene=$3; shift 3
  local args=()
  [ "$scene" = base ] || args=(--scene "$scene")
  if ! "$MBCC" compile "$model" "${args[@]}" "$@" -o "$out/$name" > "$tmp/log" 2>&1; then
    echo "golden: mbcc compile $model ${args[*]} $*: $(grep -m1 error "$tmp/log")"
    fail=1
  fi
  n=$((n + 1))
}

for f in models/*.yaml tests/models/*.yaml tests/extremes/models/*.yaml; do
  base=$(basename "$f" .yaml)
  case $base in _*|*.fe) continue ;; esac  # examples; FE files (fe_file)
  for sc in base $(scenes_of "$f"); do
    # reader_example's base scene does not assemble (a reader fixture)
    [ "$base" = reader_example ] && [ "$sc" = base ] && continue
    emit "$base-$sc" "$f" "$sc"
    emit "$base-$sc-float" "$f" "$sc" --real float
  done
done
MBCC_LDL_BUDGET=0 emit slider_crank_flexible-base-looped models/slider_crank_flexible.yaml base
MBCC_LDL_BUDGET=0 emit slider_crank_flexible-virtual2-looped models/slider_crank_flexible.yaml virtual2

(cd "$out" && find . -type f | LC_ALL=C sort | sed 's|^\./||' | xargs sha256sum) > "$tmp/now"
if [ "$mode" = update ]; then
  mkdir -p "$(dirname "$manifest")"
  cp "$tmp/now" "$manifest"
  echo "golden: $manifest rewritten ($(wc -l < "$manifest") files from $n compilations)"
  exit "$fail"
fi
if ! cmp -s "$tmp/now" "$manifest"; then
  echo "golden: the emitted code differs from $manifest:"
  diff "$manifest" "$tmp/now" | sed -n 's/^[<>] [0-9a-f]*  //p' | LC_ALL=C sort -u | head -40 | sed 's/^/  /'
  echo "golden: see it with scripts/golden-diff.sh REV; if intended, bash tests/golden.sh --update in a commit that names the change"
  exit 1
fi
[ "$fail" = 0 ] || exit 1
echo "golden: $(wc -l < "$manifest") emitted files from $n compilations match $manifest"
