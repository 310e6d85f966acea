// Seed 001's CUDA ray caster (../shared/seeds/001_4902059eec37378a.txt, "KERNEL.CU"; issue 17, part 2),
// rendering one frame of a volref scene with a cylindrical or spherical shell. Not yet run on a GPU
// (docs/gpu-checking.md): it is compiled wherever CMake finds a CUDA compiler, and
// tests/gpu/cuda/compare.sh runs it against volref's cuda-curvilinear profile where a GPU exists.
//
// From the seed, kept as written (modernised only where CUDA 12+ removed the API; the loops' guard below):
//   - the kernel's loops: `for (s = outAbs; s >= inAbs; s -= step)` in float, from the exit backwards;
//     regular composition `sum = lerp(sum, col, col.w * density)` over the samples with
//     sample >= isoValue, col = tex1D(transferTex, sample * transferScale); x-ray
//     maxVal = fmaxf(maxVal, sample) over the same samples, times xrayBrightness;
//   - interpolateCyl / interpolateSpher: texture coordinates coord / (size / n), outVal (0) outside
//     [0, n - 1], tex3D with unnormalised coordinates (texel i centred at i + 0.5), linear filtering,
//     cudaAddressModeClamp; the data as unsigned short read as cudaReadModeNormalizedFloat (v / 65535);
//     cubicInterpolate (the seed's tri-cubic option, --tricubic);
//   - cartToCyl / cartToSpher (atan2f(-z, x) + 2 pi when negative; lat = atan2f(y, r));
//   - rayIntersectTriangles: the bounding triangles with its 2 * geomSize.x / length(rayVect) fallback
//     when only one of the entry and exit is found (which, as written, still returns false: the flag
//     of the missing one stays false); barycentric coordinates as baryTriangleCoefs;
//   - the 9-entry float4 transfer texture, normalised coordinates, linear, clamp.
// Changed, because the seed's host is a GLUT program with its own camera and data:
//   - texture references (removed in CUDA 12) are texture objects; tex1D on the triangle texture
//     (point sampling at integer coordinates) is a read of a device array: the same values;
//   - the rays: volref's camera (core/camera/Camera.h) in double, per pixel, passed as float origin
//     and unit direction (the seed's invViewMatrix and viewport); the seed's near-plane distance s is 0
//     (the ray starts at volref's ray origin);
//   - the bounding triangles: volref's tessellation of the shell (geometry/ShellTessellation.h,
//     bounds.tessellate segments per turn, 64 when absent; the seed's report does not give its own);
//   - the data: (v - min) / (max - min) * 65535 rounded to the nearest unsigned short (the seed's
//     readVtk normalises to [0, 65535]; its rounding is not given); the table: the 9 entries
//     cuda-curvilinear builds, the scene's colour and opacity at min + j (max - min) / 8;
//   - output: the float sum (regular; regBrightness 1) or (maxVal, maxVal, maxVal, 1) (x-ray) written as
//     an EXR (volref's writer), not rgbaFloatToInt's 8 bits.
// Scenes: one volume with cylindrical bounds radius [0, R], angle [0, A], height [0, H] or spherical
// bounds radius [0, R], longitude [0, L], latitude [-F, F] with the default axes (the seed's geometry
// starts at 0 and its latitude is symmetric); render.projection composite or xray; step_units world;
// render.profile_options as cuda-curvilinear reads them (density, transfer_scale, iso_threshold,
// brightness).
//
// Usage: cuda_curvilinear SCENE.json OUT.exr [--set key=value]... [--tricubic]
// (exit 0 written, 2 the scene is not one the seed renders, 3 a CUDA error such as no GPU)
// This file holds the seed's device code and the CUDA calls (C++17, CUDA headers only);
// cuda_curvilinear_host.cpp reads the scene with volref (C++20) and calls seed001_render (seed001.h).
#include <cuda_runtime.h>

#include <algorithm>

#include <string>
#include <vector>

#include "seed001.h"

namespace {

// --- cutil_math's float3 / float4 helpers, as the seed uses them -------------------------------------
__host__ __device__ inline float3 operator+(float3 a, float3 b) { return make_float3(a.x + b.x, a.y + b.y, a.z + b.z); }
__host__ __device__ inline float3 operator-(float3 a, float3 b) { return make_float3(a.x - b.x, a.y - b.y, a.z - b.z); }
__host__ __device__ inline float3 operator*(float s, float3 a) { return make_float3(s * a.x, s * a.y, s * a.z); }
__host__ __device__ inline float3 operator/(float3 a, float3 b) { return make_float3(a.x / b.x, a.y / b.y, a.z / b.z); }
__host__ __device__ inline float dot(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
__host__ __device__ inline float3 cross(float3 a, float3 b) {
    return make_float3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
__device__ inline float length(float3 a) { return sqrtf(dot(a, a)); }
__device__ inline float3 normalize(float3 a) { return rsqrtf(dot(a, a)) * a; }
__device__ inline float lerp(float a, float b, float t) { return a + t * (b - a); }
__device__ inline float4 lerp(float4 a, float4 b, float t) {
    return make_float4(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.z + t * (b.z - a.z), a.w + t * (b.w - a.w));
}

// The one change to the seed's loops (issue 28): a ray whose `for (s = outAbs; s >= inAbs; s -= step)` has
// not ended after kGuardSteps steps is written as (R, G, B, A) = (-1, outAbs, inAbs, -1) instead of hanging
// the frame (in float32 s -= step cannot move s once outAbs >= about 2^24 step: the seed hangs there; the
// cuda-curvilinear profile marks those rays in its `fault` channel). Every other pixel is the seed's.
constexpr unsigned kGuardSteps = 4000000u;

struct Params {
    cudaTextureObject_t data;      // the seed's dataTex
    cudaTextureObject_t transfer;  // the seed's transferTex
    const float4* triangles;       // the seed's trianglesTex
    unsigned nTriangles;
    float3 geomSize;               // cylinder: (R, angle, H); sphere: (R, longitude, latitude), radians
    int geomType;                  // 0 cylindrical, 1 spherical
    int3 dataDim;                  // width, height, depth
    const float3* origins;         // per pixel (the seed's O), in the seed's frame (world - centre)
    const float3* directions;      // per pixel (the seed's vect), unit
    float4* output;
    unsigned dispWidth, dispHeight;
    float step, density, regBrightness, xrayBrightness, isoValue, transferScale;
    int triCubic, compoType;
};

__device__ float pi() { return 4.0f * atanf(1.0f); }
__device__ float det(float2 u, float2 v) { return (u.x * v.y) - (u.y * v.x); }

__device__ float3 cartToCyl(const float3& point) {
    float angle = atan2f(-point.z, point.x);
    if (angle < 0) angle += 8.0f * atanf(1.0f);
    return make_float3(sqrtf((point.z * point.z) + (point.x * point.x)), angle, point.y);
}

__device__ float3 cartToSpher(const float3& point) {
    float r = sqrtf((point.z * point.z) + (point.x * point.x));
    float R = sqrtf((point.x * point.x) + (point.y * point.y) + (point.z * point.z));
    float longit = atan2f(-point.z, point.x);
    if (longit < 0) longit += 2.0f * pi();
    float lat = atan2f(point.y, r);
    return make_float3(R, longit, lat);
}

__device__ float3 baryTriangleCoefs(const float3& P0, const float3& P1, const float3& P2, const float3& point) {
    // (u, v) orthonormal basis of the triangle plane
    float3 u = normalize(P1 - P0);
    float3 v = normalize(cross(cross(u, P2 - P0), u));
    float2 P0P = make_float2(dot(point - P0, u), dot(point - P0, v));
    float2 P1P = make_float2(dot(point - P1, u), dot(point - P1, v));
    float2 P2P = make_float2(dot(point - P2, u), dot(point - P2, v));
    float A = det(P1P, P2P);
    float B = det(P2P, P0P);
    float C = det(P0P, P1P);
    float delta = A + B + C;
    return make_float3(A / delta, B / delta, C / delta);
}

__device__ float3 vertex(const Params& p, unsigned i) {
    const float4 v = p.triangles[i];
    return make_float3(v.x, v.y, v.z);
}

__device__ bool inTriangle(float3 baryCoefs) { return baryCoefs.x >= 0 && baryCoefs.y >= 0 && baryCoefs.z >= 0; }

__device__ bool rayIntersectTriangles(const Params& p, const float3& rayOrig, const float3& rayVect, float* inAbs,
                                      float* outAbs) {
    bool inAbsFound = false;
    bool outAbsFound = false;
    float inAbsVal = 0.0f, outAbsVal = 0.0f;  // the seed leaves them uninitialised
    for (unsigned i = 0; i < p.nTriangles; i++) {
        float3 P0 = vertex(p, 3 * i);
        float3 P1 = vertex(p, (3 * i) + 1);
        float3 P2 = vertex(p, (3 * i) + 2);
        float3 n = cross(P1 - P0, P2 - P0);
        float d = dot(n, rayVect);
        if (d > 0) {
            float s = dot(n, P0 - rayOrig) / d;
            float3 baryCoefs = baryTriangleCoefs(P0, P1, P2, rayOrig + (s * rayVect));
            if (inTriangle(baryCoefs)) {
                outAbsVal = outAbsFound ? fmaxf(outAbsVal, s) : s;
                outAbsFound = true;
            }
        }
        if (d < 0) {
            float s = dot(n, P0 - rayOrig) / d;
            float3 baryCoefs = baryTriangleCoefs(P0, P1, P2, rayOrig + (s * rayVect));
            if (inTriangle(baryCoefs)) {
                inAbsVal = inAbsFound ? fminf(inAbsVal, s) : s;
                inAbsFound = true;
            }
        }
    }
    // The seed's fallback assigns the missing value but not its flag, so the return below is false
    // whenever it applies: a ray with only an entry or only an exit is not rendered (kept as written).
    if (inAbsFound && !outAbsFound) outAbsVal = inAbsVal + 2 * p.geomSize.x / length(rayVect);
    if (!inAbsFound && outAbsFound) inAbsVal = outAbsVal - 2 * p.geomSize.x / length(rayVect);
    *inAbs = inAbsVal;
    *outAbs = outAbsVal;
    return outAbsVal >= inAbsVal && outAbsFound && inAbsFound;
}

__device__ float3 cubicInterpMixture(float x) {
    float i = floorf(x);
    float a = x - i;
    float a2 = a * a;
    float a3 = a * a2;
    float w0 = -a3 + (2 * a2) - a;
    float w1 = a3 - (2 * a2) + 1;
    float w2 = -a3 + a2 + a;
    float w3 = a3 - a2;
    return make_float3(i - (w0 / (w0 + w1)), i + 1 + (w3 / (w2 + w3)), w2 + w3);
}

__device__ float cubicInterpolate(const Params& p, const float3& texCoord) {
    float3 mixX = cubicInterpMixture(texCoord.x);
    float3 mixY = cubicInterpMixture(texCoord.y);
    float3 mixZ = cubicInterpMixture(texCoord.z);
    float vX0Y0Z0 = tex3D<float>(p.data, mixX.x, mixY.x, mixZ.x);
    float vX0Y1Z0 = tex3D<float>(p.data, mixX.x, mixY.y, mixZ.x);
    float vX0Y0Z1 = tex3D<float>(p.data, mixX.x, mixY.x, mixZ.y);
    float vX0Y1Z1 = tex3D<float>(p.data, mixX.x, mixY.y, mixZ.y);
    float vX1Y0Z0 = tex3D<float>(p.data, mixX.y, mixY.x, mixZ.x);
    float vX1Y1Z0 = tex3D<float>(p.data, mixX.y, mixY.y, mixZ.x);
    float vX1Y0Z1 = tex3D<float>(p.data, mixX.y, mixY.x, mixZ.y);
    float vX1Y1Z1 = tex3D<float>(p.data, mixX.y, mixY.y, mixZ.y);
    float vY0Z0 = lerp(vX0Y0Z0, vX1Y0Z0, mixX.z);
    float vY1Z0 = lerp(vX0Y1Z0, vX1Y1Z0, mixX.z);
    float vZ0 = lerp(vY0Z0, vY1Z0, mixY.z);
    float vY0Z1 = lerp(vX0Y0Z1, vX1Y0Z1, mixX.z);
    float vY1Z1 = lerp(vX0Y1Z1, vX1Y1Z1, mixX.z);
    float vZ1 = lerp(vY0Z1, vY1Z1, mixY.z);
    return lerp(vZ0, vZ1, mixZ.z);
}

__device__ float interpolateCyl(const Params& p, const float3& point, float outVal, int triCubic) {
    float lengthStep = p.geomSize.x / p.dataDim.x;
    float angleStep = p.geomSize.y / p.dataDim.y;
    float heightStep = p.geomSize.z / p.dataDim.z;
    float3 cylCoord = cartToCyl(point);
    float3 texCoord = cylCoord / make_float3(lengthStep, angleStep, heightStep);
    if (texCoord.x < 0 || texCoord.x > p.dataDim.x - 1 || texCoord.y < 0 || texCoord.y > p.dataDim.y - 1 ||
        texCoord.z < 0 || texCoord.z > p.dataDim.z - 1)
        return outVal;
    if (triCubic) return cubicInterpolate(p, texCoord);
    return tex3D<float>(p.data, texCoord.x, texCoord.y, texCoord.z);
}

__device__ float interpolateSpher(const Params& p, const float3& point, float outVal, int triCubic) {
    float lengthStep = p.geomSize.x / p.dataDim.z;
    float longStep = p.geomSize.y / p.dataDim.x;
    float latStep = 2 * p.geomSize.z / p.dataDim.y;
    float3 spherCoord = cartToSpher(point) + make_float3(0, 0, p.geomSize.z);
    float3 texCoord = make_float3(spherCoord.y / longStep, spherCoord.z / latStep, spherCoord.x / lengthStep);
    if (texCoord.x < 0 || texCoord.x > p.dataDim.x - 1 || texCoord.y < 0 || texCoord.y > p.dataDim.y - 1 ||
        texCoord.z < 0 || texCoord.z > p.dataDim.z - 1)
        return outVal;
    if (triCubic) return cubicInterpolate(p, texCoord);
    return tex3D<float>(p.data, texCoord.x, texCoord.y, texCoord.z);
}

__device__ float interpolate(const Params& p, float3 point, float outVal, int triCubic) {
    return p.geomType == 0 ? interpolateCyl(p, point, outVal, triCubic) : interpolateSpher(p, point, outVal, triCubic);
}

__global__ void kernel(Params p) {
    unsigned x = blockIdx.x * blockDim.x + threadIdx.x;
    unsigned y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= p.dispWidth || y >= p.dispHeight) return;
    const unsigned i = y * p.dispWidth + x;
    float3 O = p.origins[i];
    float3 vect = p.directions[i];
    float s = 0.0f;  // the seed's distance to its viewport: volref's rays start at their origin
    float inAbs, outAbs;
    bool ok = rayIntersectTriangles(p, O, vect, &inAbs, &outAbs);
    p.output[i] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
    if (ok && outAbs >= s) {
        inAbs = fmaxf(s, inAbs);
        if (p.compoType == 0) {
            float4 sum = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
            unsigned guard_ = 0;  // the guard (below): not the seed's
            for (float s = outAbs; s >= inAbs && guard_ < kGuardSteps; s -= p.step, ++guard_) {
                float sample = interpolate(p, O + s * vect, 0, p.triCubic);
                if (sample >= p.isoValue) {
                    // Lookup in transfer function texture
                    float4 col = tex1D<float4>(p.transfer, sample * p.transferScale);
                    // Accumulate result
                    sum = lerp(sum, col, col.w * p.density);
                }
            }
            if (guard_ >= kGuardSteps) { p.output[i] = make_float4(-1.0f, outAbs, inAbs, -1.0f); return; }
            p.output[i] = make_float4(sum.x * p.regBrightness, sum.y * p.regBrightness, sum.z * p.regBrightness,
                                      sum.w * p.regBrightness);
        } else {
            float maxVal = 0.0f;
            unsigned guard_ = 0;  // the guard (below): not the seed's
            for (float s = outAbs; s >= inAbs && guard_ < kGuardSteps; s -= p.step, ++guard_) {
                float sample = interpolate(p, O + s * vect, 0, p.triCubic);
                if (sample >= p.isoValue) maxVal = fmaxf(maxVal, sample);
            }
            if (guard_ >= kGuardSteps) { p.output[i] = make_float4(-1.0f, outAbs, inAbs, -1.0f); return; }
            maxVal *= p.xrayBrightness;
            p.output[i] = make_float4(maxVal, maxVal, maxVal, 1.0f);
        }
    }
}


std::string error_of(cudaError_t e, const char* what) { return e == cudaSuccess ? std::string() : std::string(what) + ": " + cudaGetErrorString(e); }

}  // namespace

#define SEED_CHECK(call)                                      \
    do {                                                      \
        const std::string e_ = error_of((call), #call);       \
        if (!e_.empty()) return e_;                           \
    } while (0)

std::string seed001_render(const Seed001Frame& f, std::vector<float>& rgba) {
    Params p{};
    p.geomType = f.geomType;
    p.geomSize = make_float3(f.geomSize[0], f.geomSize[1], f.geomSize[2]);
    p.dataDim = make_int3(f.dims[0], f.dims[1], f.dims[2]);
    // The data: the seed's loadData (unsigned short, normalised float reads, linear, clamp, unnormalised).
    const cudaExtent extent = make_cudaExtent(std::size_t(f.dims[0]), std::size_t(f.dims[1]), std::size_t(f.dims[2]));
    cudaChannelFormatDesc ushortDesc = cudaCreateChannelDesc<unsigned short>();
    cudaArray_t dataArray = nullptr;
    SEED_CHECK(cudaMalloc3DArray(&dataArray, &ushortDesc, extent));
    cudaMemcpy3DParms copyParams = {};
    copyParams.srcPtr = make_cudaPitchedPtr(const_cast<unsigned short*>(f.data.data()), extent.width * sizeof(unsigned short),
                                            extent.width, extent.height);
    copyParams.dstArray = dataArray;
    copyParams.extent = extent;
    copyParams.kind = cudaMemcpyHostToDevice;
    SEED_CHECK(cudaMemcpy3D(&copyParams));
    cudaResourceDesc res = {};
    res.resType = cudaResourceTypeArray;
    res.res.array.array = dataArray;
    cudaTextureDesc td = {};
    td.normalizedCoords = 0;
    td.filterMode = cudaFilterModeLinear;
    td.addressMode[0] = td.addressMode[1] = td.addressMode[2] = cudaAddressModeClamp;
    td.readMode = cudaReadModeNormalizedFloat;
    SEED_CHECK(cudaCreateTextureObject(&p.data, &res, &td, nullptr));
    // The transfer function: the seed's loadTransferFunc (9 float4, normalised coordinates, linear, clamp).
    cudaChannelFormatDesc f4 = cudaCreateChannelDesc<float4>();
    cudaArray_t tableArray = nullptr;
    SEED_CHECK(cudaMallocArray(&tableArray, &f4, 9, 0));
    SEED_CHECK(cudaMemcpy2DToArray(tableArray, 0, 0, f.table.data(), 9 * sizeof(float4), 9 * sizeof(float4), 1,
                                   cudaMemcpyHostToDevice));
    cudaResourceDesc tres = {};
    tres.resType = cudaResourceTypeArray;
    tres.res.array.array = tableArray;
    cudaTextureDesc ttd = {};
    ttd.normalizedCoords = 1;
    ttd.filterMode = cudaFilterModeLinear;
    ttd.addressMode[0] = cudaAddressModeClamp;
    ttd.readMode = cudaReadModeElementType;
    SEED_CHECK(cudaCreateTextureObject(&p.transfer, &tres, &ttd, nullptr));
    // Triangles, rays, output.
    float4* tri = nullptr;
    float3 *origins = nullptr, *directions = nullptr;
    float4* out = nullptr;
    const std::size_t pixels = std::size_t(f.width) * std::size_t(f.height);
    p.nTriangles = unsigned(f.triangles.size() / 12);
    SEED_CHECK(cudaMalloc(&tri, std::max<std::size_t>(1, f.triangles.size()) * sizeof(float)));
    SEED_CHECK(cudaMemcpy(tri, f.triangles.data(), f.triangles.size() * sizeof(float), cudaMemcpyHostToDevice));
    SEED_CHECK(cudaMalloc(&origins, pixels * sizeof(float3)));
    SEED_CHECK(cudaMemcpy(origins, f.origins.data(), pixels * sizeof(float3), cudaMemcpyHostToDevice));
    SEED_CHECK(cudaMalloc(&directions, pixels * sizeof(float3)));
    SEED_CHECK(cudaMemcpy(directions, f.directions.data(), pixels * sizeof(float3), cudaMemcpyHostToDevice));
    SEED_CHECK(cudaMalloc(&out, pixels * sizeof(float4)));
    p.triangles = tri;
    p.origins = origins;
    p.directions = directions;
    p.output = out;
    p.dispWidth = unsigned(f.width);
    p.dispHeight = unsigned(f.height);
    p.step = f.step;
    p.density = f.density;
    p.regBrightness = f.regBrightness;
    p.xrayBrightness = f.xrayBrightness;
    p.isoValue = f.isoValue;
    p.transferScale = f.transferScale;
    p.triCubic = f.triCubic;
    p.compoType = f.compoType;
    // The seed's 16 x 16 blocks.
    const dim3 blockSize(16, 16);
    const dim3 gridSize((unsigned(f.width) + 15) / 16, (unsigned(f.height) + 15) / 16);
    kernel<<<gridSize, blockSize>>>(p);
    SEED_CHECK(cudaGetLastError());
    SEED_CHECK(cudaDeviceSynchronize());
    rgba.assign(pixels * 4, 0.0f);
    SEED_CHECK(cudaMemcpy(rgba.data(), out, pixels * sizeof(float4), cudaMemcpyDeviceToHost));
    cudaDestroyTextureObject(p.data);
    cudaDestroyTextureObject(p.transfer);
    cudaFreeArray(dataArray);
    cudaFreeArray(tableArray);
    cudaFree(tri);
    cudaFree(origins);
    cudaFree(directions);
    cudaFree(out);
    return {};
}
