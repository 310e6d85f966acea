#!/usr/bin/env bash
# Installs the Debian 12 packages volref builds with, if any is missing (apt-get; sudo when not root).
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libembree-dev libtbb-dev libopenimageio-dev openimageio-tools libopenexr-dev libimath-dev zlib1g-dev
  # openimageio-tools: OpenImageIO's CMake package lists its command-line tools and fails without them
  libhwy-dev libglm-dev nlohmann-json3-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
  # bounding meshes: OBJ (tinyobjloader, its double-precision build); PLY is read by volref itself
  libtinyobjloader-dev
  # volume formats: NIfTI-1/2 (nifti_clib) and VTK XML ImageData headers (expat)
  libnifti2-dev libexpat1-dev
  # volref compare --fit and volref sweep: least-squares fits (Ceres) and the error-against-time plot (gnuplot)
  libceres-dev gnuplot-nox
  # scripts/sanitize.sh and scripts/fuzz.sh: clang with AddressSanitizer, UBSan and libFuzzer (docs/robustness.md)
  clang libclang-rt-14-dev
  # the VTK parity test (scripts/vtk-parity.sh): VTK 9.1's mappers under Debian's /usr/bin/python3 on Mesa
  # llvmpipe (libgl1-mesa-dri comes as a dependency) in Xvfb; xauth is only a recommendation of xvfb
  python3-vtk9 python3-numpy xvfb xauth
  # the Python module (python/, docs/python.md): pybind11 and Python's headers to build it; pytest and
  # OpenImageIO's Python binding (reads the CLI's EXR) for its tests (numpy is listed above)
  pybind11-dev python3-dev python3-pytest python3-openimageio
  # issue 17, the GLSL check (tests/gpu/glsl): seed 002's shader on Mesa llvmpipe through EGL's surfaceless
  # platform (no X): EGL and desktop-GL headers and libraries (GLVND), Mesa's EGL driver and llvmpipe
  libegl-dev libgl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri
  # issue 22, the vtk.js check (tests/gpu/web): Debian's Chromium (headless, SwiftShader WebGL2) and node
  chromium nodejs
  # issue 55, the VolPack check (tests/volpack): VolPack 1.0b3's headers, static library and example programs
  libvolpack1-dev
  # ---- issue 21, volref-mpi (cli/mpi/; built only when CMake finds MPI): OpenMPI's headers, libraries, mpirun ----
  libopenmpi-dev openmpi-bin
  # ---- end of issue 21 ----
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "volref: installing ${missing[*]}" >&2
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
# issue 22: npm (Debian's, unless a node install already brings one), then the vtk.js check's npm
# packages from tests/gpu/web/package-lock.json into tests/gpu/web/node_modules (git-ignored); the test
# downloads nothing.
if ! command -v npm >/dev/null; then
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends npm
fi
web="$(cd "$(dirname "$0")/.." && pwd)/tests/gpu/web"
if [ ! -f "$web/node_modules/.package-lock.json" ] || ! cmp -s "$web/package-lock.json" "$web/node_modules/.volref-lock"; then
  (cd "$web" && npm ci --no-audit --no-fund --loglevel=error && cp package-lock.json node_modules/.volref-lock)
fi
