// The interface between seed 001's CUDA code (cuda_curvilinear.cu, C++17 + CUDA) and its host
// (cuda_curvilinear_host.cpp, C++20 + volref): plain arrays only.
#pragma once
#include <string>
#include <vector>

struct Seed001Frame {
    int geomType = 0;                        // 0 cylindrical, 1 spherical
    float geomSize[3] = {1, 6.2831855f, 1};  // cylinder (R, angle, H), sphere (R, longitude, latitude); radians
    int dims[3] = {1, 1, 1};                 // beam-space width, height, depth
    std::vector<unsigned short> data;        // width fastest, read as v / 65535
    std::vector<float> table;                // 9 x RGBA
    std::vector<float> triangles;            // 3 x 4 floats per triangle (the fourth unused), seed's frame
    int width = 0, height = 0;
    std::vector<float> origins, directions;  // 3 floats per pixel, row 0 at the top; unit directions
    float step = 0.01f, density = 1.0f, regBrightness = 1.0f, xrayBrightness = 1.0f, isoValue = 0.0f,
          transferScale = 1.0f;
    int triCubic = 0, compoType = 0;         // compoType 0 regular, 1 x-ray
};

// Renders the frame on the GPU: RGBA per pixel into rgba (4 floats per pixel). Returns "" or the CUDA error.
std::string seed001_render(const Seed001Frame& frame, std::vector<float>& rgba);
