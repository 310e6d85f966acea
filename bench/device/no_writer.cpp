// volref-mpi for the device machine without volref_tools (OpenImageIO): the image is not written.
#include "core/film/ImageWriter.h"
namespace volref {
void check_output_path(const std::filesystem::path&) {}
void write_image(const Image&, const std::filesystem::path&, const glm::dvec4&) {}
}
