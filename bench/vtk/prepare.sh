# Sourced by bench/run_vtk_comparison.sh and bench/speed_at_equal_error.sh (which set root, build
# and log): prepare_vtk_bench TARGET... installs what the VTK benchmarks need when it is missing
# (python3-vtk9, python3-numpy, xvfb, xauth, openimageio-tools; apt-get, with sudo when not root) and
# builds the ninja targets named in the Release build folder $build.
prepare_vtk_bench() {
    # 1. Packages (Debian 12). VTK's Python module must be Debian's: /usr/bin/python3, not whatever
    #    python3 comes first on PATH.
    missing=""
    for pkg in python3-vtk9 python3-numpy xvfb xauth openimageio-tools; do
        dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing="$missing $pkg"
    done
    if [ -n "$missing" ]; then
        log "installing:$missing"
        sudo=""
        [ "$(id -u)" -eq 0 ] || sudo=sudo
        $sudo apt-get update
        # shellcheck disable=SC2086
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends $missing
        # llvmpipe (libgl1-mesa-dri) comes with python3-vtk9's dependencies.
    fi
    /usr/bin/python3 -c "import vtkmodules, numpy" || { log "/usr/bin/python3 cannot import vtk and numpy"; exit 1; }

    # 2. volref's CLI (Release).
    if [ ! -f "$build/build.ninja" ]; then
        log "configuring $build (Release)"
        cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
    fi
    if [ "$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$build/CMakeCache.txt")" != "Release" ]; then
        log "warning: $build is not a Release build: the timings will not mean much"
    fi
    log "building $*"
    ninja -C "$build" "$@"
}
