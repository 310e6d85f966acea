#!/usr/bin/env bash
# Builds, on this machine, what a lent GPU machine (16 cores, no Debian libraries, no MPI) needs for the
# CPU scaling runs of bench/device/run_*.sh, into bench/device/carry/ (git-ignored; about 27 MB):
#   bench/device/build.sh [BUILD_DIR]          (default build/: a Release build of this checkout)
# then, through the device tool: run `bash bench/device/run_scaling.sh` with carry ["bench/device/carry"].
#   bin/probe       render_scene's thread scaling (probe.cpp), linked against volref_core alone
#   bin/volref-mpi  cli/mpi/*.cpp linked without volref_tools (no_writer.cpp: no image is written, so
#                   OpenImageIO and its 280 libraries stay behind)
#   lib/            the libraries both need, Debian's OpenMPI 4.1.4 and PMIx and every library of their
#                   plugins (not glibc, libstdc++ or libgcc_s: the machine's newer ones serve)
#   root/usr, root/etc  OpenMPI's and PMIx's plugin and help trees, used in place through OPAL_PREFIX
#   scenes/         the scaling scenes (docs/performance.md, "16 cores, measured")
# Checked in a clean Debian 12 chroot without OpenMPI (../shared/tools/fresh-debian's base) before use.
set -euo pipefail
P=$(cd "$(dirname "$0")/../.." && pwd); B=$(cd "${1:-$P/build}" && pwd); D=$P/bench/device; C=$D/carry
S=$(mktemp -d); trap 'rm -rf "$S"' EXIT
mkdir -p "$S/bin" "$S/lib" "$S/root" "$C"
CXX="g++ -O3 -DNDEBUG -ffp-contract=off -std=c++20 -I$P"
$CXX -o "$S/bin/probe" "$D/probe.cpp" -L"$B" -lvolref_core -lhwy -Wl,-rpath,'$ORIGIN/../lib'
$CXX -DOMPI_SKIP_MPICXX=1 -I/usr/lib/x86_64-linux-gnu/openmpi/include -o "$S/bin/volref-mpi" "$P"/cli/mpi/*.cpp \
  "$D/no_writer.cpp" -L"$B" -lvolref_core -ltbb -lmpi -Wl,-rpath,'$ORIGIN/../lib'
cp /usr/bin/orterun /usr/bin/orted "$S/bin/"
for p in /usr/lib/x86_64-linux-gnu/openmpi /usr/lib/x86_64-linux-gnu/pmix2 /usr/share/openmpi /etc/openmpi; do
  mkdir -p "$S/root$(dirname $p)"; cp -a "$p" "$S/root$(dirname $p)/"
done
rm -rf "$S/root/usr/lib/x86_64-linux-gnu/openmpi/include" "$S/root/usr/lib/x86_64-linux-gnu/pmix2/include"
find "$S/root" -name "*.a" -delete
LD_LIBRARY_PATH=$B ldd $(find "$S/root" -name "*.so*" -type f) "$S"/bin/* "$B/libvolref_core.so.0" 2>/dev/null \
  | awk '/=>/{print $3}' | sort -u | grep -v -E '/(libc|libm|libpthread|libdl|librt|libstdc\+\+|libgcc_s|ld-linux-x86-64)\.so' \
  | while read -r l; do cp -L "$l" "$S/lib/"; done
cp -L /usr/lib/x86_64-linux-gnu/libtbbmalloc_proxy.so.2 /usr/lib/x86_64-linux-gnu/libtbbmalloc.so.2 "$S/lib/"
# run_allocator.sh / run_partitioner.sh compare against an earlier libvolref_core: put it in old/ or mid/
# of $S by hand (OLD_CORE=path, MID_CORE=path) when rerunning those.
[ -n "${OLD_CORE:-}" ] && { mkdir -p "$S/old"; cp -L "$OLD_CORE" "$S/old/libvolref_core.so.0"; }
[ -n "${MID_CORE:-}" ] && { mkdir -p "$S/mid"; cp -L "$MID_CORE" "$S/mid/libvolref_core.so.0"; }
(cd "$S" && tar czf "$C/bundle.tgz" $(ls -d lib bin root old mid 2>/dev/null))
rm -rf "$C/scenes"; cp -r "$D/scenes" "$C/scenes"
cp "$P/bench/vtk/scenes/composite.json" "$P/reference_scenes/default.json" "$C/scenes/"
du -sh "$C"
