#!/usr/bin/env bash
# Runs on the GPU machine (16 cores) from the repository root with device/ carried:
#   bash bench/device/run_scaling.sh (carry bench/device/carry)   -> $OUT/env.txt, $OUT/probe.jsonl, $OUT/mpi.jsonl, $OUT/log.txt
# 1. thread scaling of render_scene (bench/device/probe.cpp): the adaptive scene at tile sides 16, 8, 4 and
#    tile_side()'s choice, and the benchmark frame; 2. volref-mpi (no image written) at 1..16 ranks on
#    strong, weak and adaptive scenes, with Debian's OpenMPI 4.1.4 carried (bench/device/build.sh).
set -uo pipefail
O=${OUT:-/tmp/out}; mkdir -p $O
cd "$(dirname "$0")/carry"
{ date; nproc; lscpu | grep -E "Model name|Core|Socket"; ldd --version | head -1; command -v mpirun; ls -d /usr/lib/x86_64-linux-gnu/openmpi /usr/lib/x86_64-linux-gnu/pmix2 2>&1; } > $O/env.txt 2>&1
cat $O/env.txt
tar xzf bundle.tgz || exit 3
export LD_LIBRARY_PATH=$PWD/lib
export OPAL_PREFIX=$PWD/root/usr PMIX_INSTALL_PREFIX=$PWD/root/usr/lib/x86_64-linux-gnu/pmix2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 \
  OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_pml=ob1 OMPI_MCA_btl=self,vader OMPI_MCA_osc=^ucx \
  OMPI_MCA_mca_base_component_show_load_errors=0 OMPI_MCA_plm=isolated
M="bin/orterun -q --bind-to none"
# a quick MPI check first: if it fails, say so and go on with the probe
timeout 30 $M -np 2 bin/volref-mpi render scenes/weak1.json -o /tmp/w.img --threads 1 --timing > $O/mpicheck.txt 2>&1
echo "mpi check rc=$?"; tail -5 $O/mpicheck.txt
S=scenes; T=${THREADS:-1,2,4,8,16}
timeout ${PROBE_S:-200} bin/probe 3 $T $S/adaptive.json --tile 16 -- $S/adaptive.json --tile 8 -- $S/adaptive.json --tile 4 \
  -- $S/adaptive.json -- $S/composite.json -- $S/composite.json --set render.profile=fast --set render.step=2 \
  -- $S/strong.json > $O/probe.jsonl 2> $O/probe.err; echo "probe rc=$?"; cat $O/probe.jsonl
for round in $(seq ${ROUNDS:-2}); do
  for np in ${NPS:-1 2 4 8 16}; do
    for sc in strong adaptive weak$np; do
      t0=$(date +%s.%N)
      timeout 60 $M -np $np bin/volref-mpi render $S/$sc.json -o /tmp/o.img --threads 1 --timing > /tmp/m.txt 2>&1; rc=$?
      t1=$(date +%s.%N)
      echo "{\"round\": $round, \"np\": $np, \"scene\": \"$sc\", \"rc\": $rc, \"wall_s\": $(awk "BEGIN{print $t1 - $t0}"), \"timing\": $(sed -n 's/^volref: timing //p' /tmp/m.txt | tail -1 | grep . || echo null)}" | tee -a $O/mpi.jsonl
      [ $rc = 0 ] || tail -3 /tmp/m.txt
    done
  done
done
