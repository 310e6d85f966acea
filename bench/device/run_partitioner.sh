#!/usr/bin/env bash
# Fourth device batch: one task per tile (simple_partitioner, lib/) against TBB's auto_partitioner (mid/:
# the candidates' scratch vector only; old/: the session's start), 16 threads, 3 interleaved rounds, on the
# adaptive scene (tiles 8 = tile_side's choice, and 4) and the fixed-step benchmark frames. -> $OUT/part16.jsonl
set -uo pipefail
O=${OUT:-/tmp/out}; mkdir -p $O
cd "$(dirname "$0")/carry"
tar xzf bundle.tgz || exit 3
S=scenes; L=$PWD/lib
for r in 1 2 3; do for v in mid new; do
  P=$L; [ $v = mid ] && P=$PWD/mid:$L
  LD_LIBRARY_PATH=$P bin/probe 5 16 $S/adaptive.json -- $S/adaptive.json --tile 4 -- $S/strong.json -- $S/composite.json \
    -- $S/composite.json --set render.profile=fast --set render.step=2 -- $S/default.json 2>/dev/null \
    | sed "s/^{/{\"variant\": \"$v\", \"round\": $r, /" | tee -a $O/part16.jsonl
done; done
for v in mid new; do P=$L; [ $v = mid ] && P=$PWD/mid:$L
  LD_LIBRARY_PATH=$P bin/probe 3 1 $S/adaptive.json 2>/dev/null | sed "s/^{/{\"variant\": \"$v\", /" | tee -a $O/part16.jsonl; done
