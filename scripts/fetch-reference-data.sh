#!/usr/bin/env bash
# Fetches the real reference volumes from Debian's packages into reference_scenes/data/real/ (git-ignored),
# without installing the packages' programs: `apt-get download PACKAGE` then `dpkg-deb -x` into a
# temporary folder, and only the volume is kept. A file already there is kept (the package is not
# downloaded again). scripts/setup.sh and scripts/test.sh call this; run it by hand to fetch them only.
#
#   file            package          path in the package                                    what
#   ch2.nii.gz      mricron-data     usr/share/mricron/templates/ch2.nii.gz                 MRI head, 181x217x181 u8, NIfTI-1
#   heart.vtk       mayavi2          usr/share/doc/mayavi2/examples/mayavi/data/heart.vtk   CT heart, 32x32x12 f32, VTK legacy ASCII
#   heart.vti       mayavi2          usr/share/doc/mayavi2/examples/mayavi/data/heart.vti   the same heart, VTK XML (ascii)
#   brainsmall.den  libvolpack1-dev  usr/share/doc/libvolpack1-dev/examples/brainsmall.den  MRI brain, 128x128x84 u8, VolPack
#
# The SHA-256 of each file as Debian 12 ships it is checked: a different file (a newer package) is
# reported, because the golden images in tests/golden/ were rendered from these bytes.
set -euo pipefail
cd "$(dirname "$0")/.."
dest=reference_scenes/data/real
mkdir -p "$dest"

entries=(
  "ch2.nii.gz mricron-data usr/share/mricron/templates/ch2.nii.gz"
  "heart.vtk mayavi2 usr/share/doc/mayavi2/examples/mayavi/data/heart.vtk"
  "heart.vti mayavi2 usr/share/doc/mayavi2/examples/mayavi/data/heart.vti"
  "brainsmall.den libvolpack1-dev usr/share/doc/libvolpack1-dev/examples/brainsmall.den"
)
declare -A sha256=(
  [ch2.nii.gz]=a009051127f64dc3dd554d5f5b589870ea72106d9642c21b4e7093e478cfc309
  [heart.vtk]=b2a00dcd47bcd3bfc3593ce61e17c7522de90e15443550971f5646da54d4b5b9
  [heart.vti]=04f75b87442408088080c54b94fd2a33826b01fe8e93855ddfbe22c3b9102b50
  [brainsmall.den]=eebfa050a1775f556718c2c9716cb624bc2270392e82176b1ce4812b36d4f286
)

sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
work=$(mktemp -d)
# (As root, apt-get download notes that it downloads unsandboxed: _apt cannot write to this private
# folder. The note goes to $work/apt.log and is shown only if the download fails.)
trap 'rm -rf "$work"' EXIT
updated=0

# Downloads PACKAGE's .deb into $work (once) and extracts it into $work/PACKAGE.
extract() {
  local package=$1
  [ -d "$work/$package" ] && return 0
  if ! (cd "$work" && apt-get download -q "$package" >/dev/null 2>"$work/apt.log"); then
    if [ $updated -eq 0 ]; then
      echo "fetch-reference-data: apt-get download $package failed; running apt-get update" >&2
      $sudo apt-get update -q >&2
      updated=1
    fi
    (cd "$work" && apt-get download -q "$package" >/dev/null) || {
      cat "$work/apt.log" >&2
      echo "fetch-reference-data: cannot download $package" >&2
      return 1
    }
  fi
  dpkg-deb -x "$work/${package}"_*.deb "$work/$package"
  rm -f "$work/${package}"_*.deb
}

for entry in "${entries[@]}"; do
  read -r name package inner <<<"$entry"
  out="$dest/$name"
  if [ ! -f "$out" ]; then
    echo "fetch-reference-data: $name from the Debian package $package" >&2
    extract "$package"
    if [ ! -f "$work/$package/$inner" ]; then
      echo "fetch-reference-data: $package has no $inner" >&2
      exit 1
    fi
    cp "$work/$package/$inner" "$out.tmp"
    mv "$out.tmp" "$out"
  fi
  actual=$(sha256sum "$out" | cut -d' ' -f1)
  if [ "$actual" != "${sha256[$name]}" ]; then
    echo "fetch-reference-data: warning: $out differs from the file the golden images were made from" \
         "(sha256 $actual, expected ${sha256[$name]}); the RealData tests may fail" >&2
  fi
done
echo "fetch-reference-data: $dest has ${#entries[@]} files" >&2
