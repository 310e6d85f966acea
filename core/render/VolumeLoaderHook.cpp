#include "core/render/VolumeLoaderHook.h"

#include <utility>

namespace volref {

namespace {
VolumeLoaderHook& hook_storage() {
    static VolumeLoaderHook hook;
    return hook;
}
}  // namespace

void set_volume_loader_hook(VolumeLoaderHook hook) { hook_storage() = std::move(hook); }
const VolumeLoaderHook& volume_loader_hook() { return hook_storage(); }

}  // namespace volref
