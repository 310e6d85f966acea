// volref convert IN OUT [--format F] [--type T] [--encoding raw|gzip]: reads any volume format and
// writes NRRD (.nrrd) or raw + JSON sidecar (.raw), in the input's type by default or any of the 8
// types (--type). Every argument is checked before the input is read; the output goes to a
// temporary name renamed into place, so a failure leaves no file.
#include <cstdio>
#include <optional>
#include <string>

#include "cli/ConvertCommand.h"
#include "core/Error.h"
#include "core/io/NrrdWriter.h"
#include "core/io/RawWriter.h"
#include "core/io/VolumeReader.h"

namespace volref::cli {

namespace {

std::string lower(std::string s) {
    for (char& c : s)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    return s;
}

ScalarType parse_type(const std::string& name) {
    for (ScalarType t : {ScalarType::U8, ScalarType::I8, ScalarType::U16, ScalarType::I16, ScalarType::U32,
                         ScalarType::I32, ScalarType::F32, ScalarType::F64})
        if (name == scalar_type_name(t)) return t;
    throw Error("--type: expected u8, i8, u16, i16, u32, i32, f32 or f64, got '" + name + "'");
}

}  // namespace

int run_convert(const ConvertArgs& args) {
    const std::string ext = lower(args.output.extension().string());
    if (ext != ".nrrd" && ext != ".raw")
        throw Error(args.output.string() + ": the output must be .nrrd (NRRD) or .raw (raw + JSON sidecar), got " +
                    (ext.empty() ? std::string("no extension") : "'" + args.output.extension().string() + "'"));
    if (args.encoding != "raw" && args.encoding != "gzip")
        throw Error("--encoding: expected raw or gzip, got '" + args.encoding + "'");
    const bool nrrd = ext == ".nrrd";
    std::optional<ScalarType> type;
    if (!args.type.empty()) {
        type = parse_type(args.type);
    }
    if (nrrd) check_nrrd_output_path(args.output);
    volume_format(args.input, args.format);  // a bad format fails before any reading

    const Volume volume = read_volume(args.input, args.format);
    if (nrrd) {
        NrrdWriteOptions o;
        o.type = type.value_or(volume.type);  // the input's type unless --type says otherwise
        o.encoding = args.encoding == "gzip" ? NrrdWriteOptions::Encoding::Gzip : NrrdWriteOptions::Encoding::Raw;
        o.comments.push_back("volref convert from " + args.input.filename().string() + " (" +
                             scalar_type_name(volume.type) + ")");
        write_nrrd(volume, args.output, o);
    } else {
        RawWriteOptions o;
        o.type = type.value_or(volume.type);
        o.gzip = args.encoding == "gzip";
        write_raw(volume, args.output, o);
    }
    std::fprintf(stderr, "volref: converted %lld x %lld x %lld %s to %s\n", static_cast<long long>(volume.dims[0]),
                 static_cast<long long>(volume.dims[1]), static_cast<long long>(volume.dims[2]),
                 scalar_type_name(volume.type), args.output.string().c_str());
    std::printf("%s\n", args.output.string().c_str());
    return 0;
}

}  // namespace volref::cli
