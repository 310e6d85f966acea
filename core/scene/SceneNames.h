// SceneNames: the scene format's one list of names for each enumerated value (docs/scene-format.md).
//
// The loader reads them (SceneLoader.cpp: ObjectReader::choice over these tables), the writer writes
// them (SceneWriter.h: a resolved Scene back to the format), and trace / explain print them. A name
// is written in one place only: a new value, or a renamed one, is one line here. Where a table lists
// an alias (a second name read for the same value, e.g. integrator "midpoint"), the canonical name comes first:
// name_of returns the first name of a value.
#pragma once
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/Error.h"
#include "core/scene/JsonReader.h"
#include "core/scene/Scene.h"

namespace volref::scene_names {

using json_reader::Choice;

inline constexpr Choice<FieldSpec::Kind> kFields[] = {{"constant", FieldSpec::Kind::Constant},
                                                      {"linear", FieldSpec::Kind::Linear},
                                                      {"radial", FieldSpec::Kind::Radial},
                                                      {"marschner-lobb", FieldSpec::Kind::MarschnerLobb},
                                                      {"gaussian", FieldSpec::Kind::Gaussian},
                                                      {"cells", FieldSpec::Kind::Cells}};
// The two shells are entries 2 and 3 (parse_shell reads them alone).
inline constexpr Choice<BoundsSpec::Type> kBounds[] = {{"box", BoundsSpec::Type::Box},
                                                       {"mesh", BoundsSpec::Type::Mesh},
                                                       {"cylindrical", BoundsSpec::Type::Cylindrical},
                                                       {"spherical", BoundsSpec::Type::Spherical},
                                                       {"tetrahedra", BoundsSpec::Type::Tetrahedra}};
// volume.bounds.overlap (tetrahedra); "count" is planned (SceneLoader: not implemented yet).
inline constexpr Choice<BoundsSpec::Overlap> kOverlaps[] = {{"union", BoundsSpec::Overlap::Union}, {"count", BoundsSpec::Overlap::Count}};
// A spherical shell's "axes": the data's axis order (SphericalShell::axes holds these indices).
inline constexpr Choice<int> kSphericalAxes[] = {{"longitude", 0}, {"latitude", 1}, {"radius", 2}};
inline constexpr Choice<TransferSpec::Domain> kTransferDomains[] = {{"data", TransferSpec::Domain::Data},
                                                                    {"normalized", TransferSpec::Domain::Normalized}};
inline constexpr Choice<ClassificationSpec::Type> kClassifications[] = {{"isovalue", ClassificationSpec::Type::Isovalue},
                                                                        {"boundary", ClassificationSpec::Type::Boundary}};
inline constexpr Choice<ShadingSpec::Model> kShadingModels[] = {{"blinn-phong", ShadingSpec::Model::BlinnPhong},
                                                                {"phong", ShadingSpec::Model::Phong},
                                                                {"nodal", ShadingSpec::Model::Nodal}};
// GradientSpec::Scheme::Default has no name: the key absent.
inline constexpr Choice<GradientSpec::Scheme> kGradientSchemes[] = {{"central", GradientSpec::Scheme::Central},
                                                                    {"forward", GradientSpec::Scheme::Forward},
                                                                    {"analytic", GradientSpec::Scheme::Analytic}};
inline constexpr Choice<Interpolation> kInterpolations[] = {{"nearest", Interpolation::Nearest},
                                                            {"trilinear", Interpolation::Trilinear},
                                                            {"tricubic-bspline", Interpolation::TricubicBSpline},
                                                            {"tricubic-catmull-rom", Interpolation::TricubicCatmullRom}};
inline constexpr Choice<VolumeSpec::Classify> kClassify[] = {{"post", VolumeSpec::Classify::Post},
                                                             {"pre", VolumeSpec::Classify::Pre}};
inline constexpr Choice<LightSpec::Type> kLights[] = {{"headlight", LightSpec::Type::Headlight},
                                                      {"directional", LightSpec::Type::Directional}};
// CameraSpec::Type::Default has no name: the key "camera" absent.
inline constexpr Choice<CameraSpec::Type> kCameras[] = {{"perspective", CameraSpec::Type::Perspective},
                                                        {"orthographic", CameraSpec::Type::Orthographic},
                                                        {"matrices", CameraSpec::Type::Matrices}};
inline constexpr Choice<Projection> kProjections[] = {{"composite", Projection::Composite}, {"mip", Projection::Mip},
                                                      {"minip", Projection::Minip},         {"average", Projection::Average},
                                                      {"first-hit", Projection::FirstHit},  {"xray", Projection::Xray}};
inline constexpr Choice<CompositeOrder> kOrders[] = {{"front-to-back", CompositeOrder::FrontToBack},
                                                     {"back-to-front", CompositeOrder::BackToFront}};
inline constexpr Choice<StepUnits> kStepUnits[] = {{"voxel", StepUnits::Voxel}, {"world", StepUnits::World}};
// "midpoint": an alias of "fixed", read so that scene files that name it load.
inline constexpr Choice<IntegrationMethod> kIntegrators[] = {{"fixed", IntegrationMethod::Fixed},
                                                             {"adaptive", IntegrationMethod::Adaptive},
                                                             {"midpoint", IntegrationMethod::Fixed}};
inline constexpr Choice<ProfileId> kProfiles[] = {{"reference", ProfileId::Reference},
                                                  {"vtk-gpu", ProfileId::VtkGpu},
                                                  {"glsl-basic", ProfileId::GlslBasic},
                                                  {"ospray", ProfileId::Ospray},
                                                  {"cuda-curvilinear", ProfileId::CudaCurvilinear},
                                                  {"vtk-cpu", ProfileId::VtkCpu},
                                                  {"fast", ProfileId::Fast},
                                                  {"vtk-js", ProfileId::VtkJs},
                                                  {"volumizer", ProfileId::Volumizer},
                                                  {"volpack", ProfileId::VolPack}};
// TextureUnit::Admissible has no name (tests only). "hardware": a deprecated alias of "h100".
inline constexpr Choice<ProfileOptions::TextureUnit> kTextureUnits[] = {{"exact", ProfileOptions::TextureUnit::Exact},
                                                                       {"h100", ProfileOptions::TextureUnit::H100},
                                                                       {"hardware", ProfileOptions::TextureUnit::H100}};
inline constexpr Choice<ProfileOptions::Kernel> kKernels[] = {{"float32", ProfileOptions::Kernel::Float32},
                                                              {"double", ProfileOptions::Kernel::Double}};
inline constexpr Choice<bool> kTextureFormats[] = {{"float", false}, {"unorm16", true}};  // data_unorm16
inline constexpr Choice<bool> kVtkJsRayBoxes[] = {{"texel", false}, {"domain", true}};   // ray_box_domain

// render.profile's rules (ProfileRules; each rule's entry in ProfileRuleTable.cpp names its table).
using Rules = ProfileRules;
inline constexpr Choice<Rules::Placement> kPlacements[] = {{"midpoints", Rules::Placement::Midpoints},
                                                           {"from-entry", Rules::Placement::FromEntry},
                                                           {"from-exit", Rules::Placement::FromExit},
                                                           {"slices", Rules::Placement::Slices}};
inline constexpr Choice<Rules::StepCount> kStepCounts[] = {{"through-exit", Rules::StepCount::ThroughExit},
                                                           {"before-exit", Rules::StepCount::BeforeExit}};
// RayBox::Given is written as {"min", "max"}.
inline constexpr Choice<Rules::RayBox> kRayBoxes[] = {{"domain", Rules::RayBox::Domain}, {"texel", Rules::RayBox::Texel}};
inline constexpr Choice<Rules::VoxelLength> kVoxelLengths[] = {{"spacing", Rules::VoxelLength::Spacing},
                                                               {"extent-over-samples", Rules::VoxelLength::ExtentOverSamples}};
inline constexpr Choice<Rules::Correction> kCorrections[] = {{"pow", Rules::Correction::Power},
                                                             {"exact", Rules::Correction::Exact},
                                                             {"none", Rules::Correction::None},
                                                             {"extinction", Rules::Correction::Extinction}};
inline constexpr Choice<Rules::Compositing> kCompositings[] = {{"optical-depth", Rules::Compositing::OpticalDepth},
                                                               {"product", Rules::Compositing::Product},
                                                               {"opacity-sum", Rules::Compositing::OpacitySum},
                                                               {"lerp", Rules::Compositing::Lerp}};
// Stop::None is "none"; the others are written {"<name>": value}.
inline constexpr Choice<Rules::Stop> kStops[] = {{"alpha_above", Rules::Stop::AlphaAbove},
                                                 {"alpha_at_least", Rules::Stop::AlphaAtLeast},
                                                 {"transmittance_at_most", Rules::Stop::TransmittanceAtMost}};
inline constexpr Choice<Rules::TableCoordinate> kTableCoordinates[] = {
    {"data-range", Rules::TableCoordinate::DataRange},
    {"data-range-times-transfer-scale", Rules::TableCoordinate::DataRangeTimesTransferScale}};
inline constexpr Choice<Rules::Arithmetic> kArithmetics[] = {{"double", Rules::Arithmetic::Double},
                                                             {"float32", Rules::Arithmetic::Float32}};
inline constexpr Choice<Rules::Gradient> kRuleGradients[] = {{"central", Rules::Gradient::Central},
                                                             {"forward", Rules::Gradient::Forward},
                                                             {"central-in-domain", Rules::Gradient::CentralInDomain}};
// The slicers' rules (conventions section 9, "Slice-order renderers").
using SliceRules = Rules::Slices;
inline constexpr Choice<SliceRules::Orientation> kSliceOrientations[] = {{"viewport", SliceRules::Orientation::Viewport},
                                                                       {"axis", SliceRules::Orientation::Axis},
                                                                       {"spherical", SliceRules::Orientation::Spherical}};
inline constexpr Choice<SliceRules::Range> kSliceRanges[] = {{"object", SliceRules::Range::Object},
                                                           {"view_volume", SliceRules::Range::ViewVolume}};
inline constexpr Choice<SliceRules::First> kSliceFirsts[] = {{"bound", SliceRules::First::Bound}, {"half", SliceRules::First::Half}};
inline constexpr Choice<SliceRules::Order> kSliceOrders[] = {{"back-to-front", SliceRules::Order::BackToFront},
                                                           {"front-to-back", SliceRules::Order::FrontToBack}};
inline constexpr Choice<Rules::Texture> kTextures[] = {{"3d", Rules::Texture::Texture3d}, {"2d", Rules::Texture::Texture2d}};
inline constexpr Choice<Rules::TexelFormat> kTexelFormats[] = {{"float", Rules::TexelFormat::Float},
                                                              {"unorm16", Rules::TexelFormat::Unorm16},
                                                              {"unorm8", Rules::TexelFormat::Unorm8}};
// TextureWindow::Given is written [lo, hi].
inline constexpr Choice<Rules::TextureWindow> kTextureWindows[] = {{"transfer-rows", Rules::TextureWindow::TransferRows},
                                                                  {"data-range", Rules::TextureWindow::DataRange}};
inline constexpr Choice<Rules::TableLookup> kTableLookups[] = {{"texture", Rules::TableLookup::Texture},
                                                              {"linear", Rules::TableLookup::Linear},
                                                              {"nearest", Rules::TableLookup::Nearest}};
inline constexpr Choice<Rules::TableFormat> kTableFormats[] = {{"float", Rules::TableFormat::Float}, {"unorm8", Rules::TableFormat::Unorm8}};
inline constexpr Choice<Rules::SliceClassify> kSliceClassifies[] = {{"post", Rules::SliceClassify::Post},
                                                                   {"pre-unweighted", Rules::SliceClassify::PreUnweighted}};
inline constexpr Choice<Rules::FrameBuffer> kFrameBuffers[] = {{"double", Rules::FrameBuffer::Double},
                                                              {"rgba32f", Rules::FrameBuffer::Rgba32f},
                                                              {"rgba16f", Rules::FrameBuffer::Rgba16f},
                                                              {"rgba8", Rules::FrameBuffer::Rgba8}};
inline constexpr Choice<Rules::Rounding> kRoundings[] = {{"nearest", Rules::Rounding::Nearest}, {"truncate", Rules::Rounding::Truncate}};
inline constexpr Choice<Rules::BlendProducts> kBlendProducts[] = {{"exact", Rules::BlendProducts::Exact},
                                                                 {"rounded", Rules::BlendProducts::Rounded},
                                                                 {"llvmpipe", Rules::BlendProducts::Llvmpipe}};
inline constexpr Choice<Rules::TextureFilter> kTextureFilters[] = {{"exact", Rules::TextureFilter::Exact},
                                                                  {"fixed8", Rules::TextureFilter::Fixed8}};
inline constexpr Choice<Rules::Blend> kBlends[] = {{"src-alpha", Rules::Blend::SrcAlpha},
                                                  {"premultiplied", Rules::Blend::Premultiplied},
                                                  {"max", Rules::Blend::Max}};
inline constexpr Choice<Rules::BlendAlpha> kBlendAlphas[] = {{"src-alpha", Rules::BlendAlpha::SrcAlpha}, {"one", Rules::BlendAlpha::One}};
inline constexpr Choice<bool> kNormals[] = {{"-gradient", false}, {"+gradient", true}};  // normal_along_gradient

// The name `value` is written as: the table's first entry for it. A value with no name (a Default, a
// tests-only value) is a programming error: it throws.
template <class E>
const char* name_of(std::span<const Choice<E>> table, E value) {
    for (const Choice<E>& c : table)
        if (c.value == value) return c.name.data();  // every name is a string literal (NUL-terminated)
    throw Error("internal: a value with no name in the scene format");
}
template <class E, std::size_t N>
const char* name_of(const Choice<E> (&table)[N], E value) {
    return name_of(std::span<const Choice<E>>(table), value);
}

// The value named `name` in `table` (aliases included), or nothing.
template <class E>
std::optional<E> value_of(std::span<const Choice<E>> table, std::string_view name) {
    for (const Choice<E>& c : table)
        if (c.name == name) return c.value;
    return std::nullopt;
}
template <class E, std::size_t N>
std::optional<E> value_of(const Choice<E> (&table)[N], std::string_view name) {
    return value_of(std::span<const Choice<E>>(table), name);
}

// The table's names for a message: "a, b or c" (aliases included).
template <class E>
std::string listing(std::span<const Choice<E>> table) {
    std::string s;
    const std::size_t n = table.size();
    for (std::size_t i = 0; i < n; ++i) s += std::string(i == 0 ? "" : i + 1 == n ? " or " : ", ") + std::string(table[i].name);
    return s;
}
template <class E, std::size_t N>
std::string listing(const Choice<E> (&table)[N]) {
    return listing(std::span<const Choice<E>>(table));
}

}  // namespace volref::scene_names
