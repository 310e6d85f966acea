// volref's core API in one include: what libvolref_core (volref::volref_core) provides, rendering to
// memory with no image-file or comparison dependency (installed as <volref/volref_core.h>'s folder on
// the path: #include "volref_core.h"). "volref.h" adds writing image files (volref::volref_tools).
// See README.md and docs/architecture.md.
#pragma once
#include "core/Conventions.h"
#include "core/Error.h"
#include "core/camera/Camera.h"
#include "core/film/Image.h"
#include "core/grid/ProceduralField.h"
#include "core/grid/Volume.h"
#include "core/integrate/Integrator.h"
#include "core/io/VolumeReader.h"
#include "core/render/Renderer.h"
#include "core/sample/Trilinear.h"
#include "core/sample/VolumeSampler.h"
#include "core/scene/Scene.h"
#include "core/scene/SceneLoader.h"
#include "geometry/BoundingGeometry.h"
#include "transfer/OpacityCorrection.h"
#include "transfer/TransferFunction.h"
