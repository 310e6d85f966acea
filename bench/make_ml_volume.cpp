// make_ml_volume N OUT.nrrd [f32|f64]: writes the Marschner-Lobb test volume (fm 6, alpha 0.25; the
// procedural field "marschner-lobb" of docs/scene-format.md) of N^3 voxels, origin 0, spacing 1, as a
// NRRD file of floats (default) or doubles, for the memory and scaling benchmarks (bench/scaling.sh).
#include <cstdio>
#include <exception>
#include <string>

#include "core/grid/ProceduralField.h"
#include "core/io/NrrdWriter.h"

int main(int argc, char** argv) {
    if (argc < 3 || argc > 4) {
        std::fprintf(stderr, "usage: make_ml_volume N OUT.nrrd [f32|f64]\n");
        return 2;
    }
    try {
        const long n = std::stol(argv[1]);
        const std::string type = argc == 4 ? argv[3] : "f32";
        if (n < 2 || (type != "f32" && type != "f64")) {
            std::fprintf(stderr, "usage: make_ml_volume N OUT.nrrd [f32|f64] (N >= 2)\n");
            return 2;
        }
        volref::FieldSpec ml;
        ml.kind = volref::FieldSpec::Kind::MarschnerLobb;
        ml.dims = {n, n, n};
        ml.fm = 6.0;
        ml.alpha = 0.25;
        const volref::Volume v = volref::make_procedural_volume(ml, glm::dvec3(0.0), glm::dvec3(1.0));
        volref::NrrdWriteOptions options;
        options.type = type == "f32" ? volref::ScalarType::F32 : volref::ScalarType::F64;
        volref::write_nrrd(v, argv[2], options);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "make_ml_volume: %s\n", e.what());
        return 1;
    }
    return 0;
}
