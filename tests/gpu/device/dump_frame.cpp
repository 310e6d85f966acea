// Link-time stand-in for seed001_render (tests/gpu/cuda/seed001.h): instead of rendering, writes the frame
// the project's host built to $SEED001_FRAME_OUT, so that a GPU machine without volref's libraries can
// render it with the project's own kernel (seed001_harness.cpp). Built with the project's
// cuda_curvilinear_host.cpp (prepare.sh).
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
#include "seed001.h"

template <class T> static void put(FILE* f, const std::vector<T>& v) {
    unsigned long long n = v.size();
    fwrite(&n, sizeof n, 1, f);
    fwrite(v.data(), sizeof(T), v.size(), f);
}

std::string seed001_render(const Seed001Frame& fr, std::vector<float>& rgba) {
    const char* path = std::getenv("SEED001_FRAME_OUT");
    if (!path) return "SEED001_FRAME_OUT not set";
    FILE* f = std::fopen(path, "wb");
    if (!f) return "cannot write frame";
    fwrite(&fr.geomType, sizeof(int), 1, f);
    fwrite(fr.geomSize, sizeof(float), 3, f);
    fwrite(fr.dims, sizeof(int), 3, f);
    put(f, fr.data); put(f, fr.table); put(f, fr.triangles);
    fwrite(&fr.width, sizeof(int), 1, f); fwrite(&fr.height, sizeof(int), 1, f);
    put(f, fr.origins); put(f, fr.directions);
    const float fl[6] = {fr.step, fr.density, fr.regBrightness, fr.xrayBrightness, fr.isoValue, fr.transferScale};
    fwrite(fl, sizeof(float), 6, f);
    const int in[2] = {fr.triCubic, fr.compoType};
    fwrite(in, sizeof(int), 2, f);
    std::fclose(f);
    rgba.assign(std::size_t(fr.width) * fr.height * 4, 0.0f);
    return "";
}
