#!/usr/bin/env bash
# Third device batch: the adaptive integrator at 16 threads before (old/) and after (lib/) its candidates'
# scratch vector, and with TBB's scalable allocator, tiles of 8 and 4; 3 interleaved rounds. -> $OUT/adaptive16.jsonl
set -uo pipefail
O=${OUT:-/tmp/out}; mkdir -p $O
cd "$(dirname "$0")/carry"
tar xzf bundle.tgz || exit 3
S=scenes; L=$PWD/lib
for v in old new; do
  if [ $v = old ]; then P=$PWD/old:$L; else P=$L; fi
  LD_LIBRARY_PATH=$P bin/probe 3 1 $S/adaptive.json --tile 8 2>/dev/null | sed "s/^{/{\"variant\": \"$v\", /" | tee -a $O/adaptive16.jsonl
done
for r in 1 2 3; do for t in 8 4; do for v in old new new-tbbmalloc; do
  P=$L; X=; [ $v = old ] && P=$PWD/old:$L; [ $v = new-tbbmalloc ] && X=$L/libtbbmalloc_proxy.so.2
  LD_PRELOAD=$X LD_LIBRARY_PATH=$P bin/probe 5 16 $S/adaptive.json --tile $t 2>/dev/null | sed "s/^{/{\"variant\": \"$v\", \"round\": $r, /" | tee -a $O/adaptive16.jsonl
done; done; done
