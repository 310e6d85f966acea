#!/usr/bin/env bash
# Second device batch: why the adaptive integrator scales 10x at 16 threads. A: threads 1 and 16 with
# glibc malloc and with TBB's scalable allocator (LD_PRELOAD); B: K independent single-thread processes at
# once (K = 1, 8, 16): if each slows down as K grows, the limit is the machine (shared cores, clocks,
# memory), not the renderer's parallel code. -> $OUT/*.jsonl, $OUT/cpu.txt
set -uo pipefail
O=${OUT:-/tmp/out}; mkdir -p $O
cd "$(dirname "$0")/carry"
{ lscpu; grep -m1 flags /proc/cpuinfo; cat /sys/devices/system/cpu/cpu0/topology/thread_siblings_list; } > $O/cpu.txt 2>&1
tar xzf bundle.tgz || exit 3
export LD_LIBRARY_PATH=$PWD/lib
S=scenes
bin/probe 3 1,16 $S/adaptive.json --tile 8 > $O/a_base.jsonl 2>/dev/null; cat $O/a_base.jsonl
LD_PRELOAD=$PWD/lib/libtbbmalloc_proxy.so.2 bin/probe 3 1,16 $S/adaptive.json --tile 8 > $O/a_tbbmalloc.jsonl 2>/dev/null; cat $O/a_tbbmalloc.jsonl
for sc in adaptive composite strong; do
  for K in 1 8 16; do
    for i in $(seq $K); do bin/probe 2 1 $S/$sc.json > /tmp/p_${sc}_${K}_$i.jsonl 2>/dev/null & done; wait
    for i in $(seq $K); do sed "s/^{/{\"K\": $K, \"i\": $i, /" /tmp/p_${sc}_${K}_$i.jsonl; done >> $O/throughput.jsonl
    echo "$sc K=$K"; grep -h -o '"min_s": [0-9.]*' /tmp/p_${sc}_${K}_*.jsonl | sort | sed -n '1p;$p'
  done
done
