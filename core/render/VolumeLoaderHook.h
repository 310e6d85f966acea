// A process-wide override of load_volume (Renderer.h): when set, load_volume(spec) returns
// hook(spec) instead of reading the spec's file or generating its field. volref-mpi (cli/mpi/) sets it so
// that each rank's PreparedVolume is built on that rank's brick of the volume (docs/architecture.md,
// "volref-mpi"); nothing else sets it. Set it before building a PreparedVolume, from one thread.
#pragma once
#include <functional>

#include "core/grid/Volume.h"
#include "core/scene/Scene.h"

namespace volref {

using VolumeLoaderHook = std::function<Volume(const VolumeSpec&)>;

// An empty function restores the default loader.
void set_volume_loader_hook(VolumeLoaderHook hook);
const VolumeLoaderHook& volume_loader_hook();

}  // namespace volref
