#!/usr/bin/env bash
# Fifth device batch (issue 31, part 1): the packets on AVX-512 (16 float / 8 double lanes, Highway's
# dispatch on that CPU) against AVX2 (8 / 4; PROBE_NO_AVX512=1), one thread, 3 interleaved rounds, on the
# benchmark frame: fast step 1 and 2, reference step 1, pre-integrated fast step 2. -> $OUT/simd.jsonl
set -uo pipefail
O=${OUT:-/tmp/out}; mkdir -p $O
cd "$(dirname "$0")/carry"
tar xzf bundle.tgz || exit 3
export LD_LIBRARY_PATH=$PWD/lib
S=scenes/composite.json
for r in 1 2 3; do for v in avx512 avx2; do
  X=; [ $v = avx2 ] && X=1
  PROBE_NO_AVX512=$X bin/probe 5 1 $S --set render.profile=fast --set render.step=1 -- $S --set render.profile=fast --set render.step=2 \
    -- $S --set render.step=1 -- $S --set render.profile=fast --set render.step=2 --set render.profile_options.preintegration=256 \
    2>/dev/null | sed "s/^{/{\"isa\": \"$v\", \"round\": $r, /" | tee -a $O/simd.jsonl
done; done
