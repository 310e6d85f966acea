// volref info FILE [--format F] [--json] [--bins N]: dims, type, spacing, origin, value range and a
// histogram of a volume file, as text (a bar chart) or JSON.
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/InfoCommand.h"
#include "core/Error.h"
#include "core/io/VolumeInfo.h"
#include "core/io/VolumeReader.h"

namespace volref::cli {

namespace {

std::string num(double x) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

std::string vec(const glm::dvec3& v) { return num(v.x) + " " + num(v.y) + " " + num(v.z); }

}  // namespace

int run_info(const InfoArgs& args) {
    if (args.bins < 1 || args.bins > 1000) throw Error("--bins: expected an integer from 1 to 1000, got " + std::to_string(args.bins));
    const std::string format = volume_format(args.input, args.format);
    const Volume v = read_volume(args.input, format);
    const VolumeSummary s = summarize(v, args.bins);
    const double width = s.finite ? (s.max - s.min) / double(args.bins) : 0.0;
    const auto bin_low = [&](int b) { return s.min + (s.max - s.min) * double(b) / double(args.bins); };

    if (args.json) {
        nlohmann::ordered_json j;
        j["file"] = args.input.string();
        j["format"] = format;
        j["dims"] = {v.dims[0], v.dims[1], v.dims[2]};
        j["voxels"] = s.voxels;
        j["type"] = scalar_type_name(v.type);
        j["spacing"] = {v.spacing.x, v.spacing.y, v.spacing.z};
        j["origin"] = {v.origin.x, v.origin.y, v.origin.z};
        j["domain_max"] = {v.domain_max().x, v.domain_max().y, v.domain_max().z};
        j["range"] = {s.min, s.max};
        j["nan"] = s.nan;
        j["infinite"] = s.infinite;
        nlohmann::ordered_json h;
        h["bins"] = args.bins;
        h["min"] = s.min;
        h["max"] = s.max;
        h["counts"] = s.histogram;
        j["histogram"] = h;
        std::printf("%s\n", j.dump(2).c_str());
        return 0;
    }
    std::printf("file:     %s\n", args.input.string().c_str());
    std::printf("format:   %s\n", format.c_str());
    std::printf("dims:     %lld x %lld x %lld (%llu voxels)\n", static_cast<long long>(v.dims[0]),
                static_cast<long long>(v.dims[1]), static_cast<long long>(v.dims[2]),
                static_cast<unsigned long long>(s.voxels));
    std::printf("type:     %s\n", scalar_type_name(v.type));
    std::printf("spacing:  %s\n", vec(v.spacing).c_str());
    std::printf("origin:   %s\n", vec(v.origin).c_str());
    std::printf("extent:   %s .. %s\n", vec(v.domain_min()).c_str(), vec(v.domain_max()).c_str());
    if (s.finite == 0) {
        std::printf("range:    no finite values\n");
    } else {
        std::printf("range:    %s .. %s\n", num(s.min).c_str(), num(s.max).c_str());
    }
    if (s.nan || s.infinite)
        std::printf("non-finite: %llu NaN, %llu infinite\n", static_cast<unsigned long long>(s.nan),
                    static_cast<unsigned long long>(s.infinite));
    if (s.finite == 0) return 0;
    std::printf("histogram (%d bins of width %s; the last includes the maximum):\n", args.bins, num(width).c_str());
    const std::uint64_t most = *std::max_element(s.histogram.begin(), s.histogram.end());
    constexpr int kBar = 40;
    for (int b = 0; b < args.bins; ++b) {
        const std::uint64_t c = s.histogram[std::size_t(b)];
        const int len = most ? int((double(c) / double(most)) * kBar + 0.5) : 0;
        std::string bar(std::size_t(len), '#');
        if (c > 0 && len == 0) bar = ".";
        std::printf("  %14s  %-*s %llu\n", num(bin_low(b)).c_str(), kBar, bar.c_str(), static_cast<unsigned long long>(c));
    }
    return 0;
}

}  // namespace volref::cli
