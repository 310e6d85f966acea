// volref: the whole public API in one include (installed as <volref/volref.h>'s folder on the path:
// #include "volref.h"): the core (volref_core.h, libvolref_core) and writing image files
// (core/film/ImageWriter.h, libvolref_tools): link volref::volref (both) or volref::volref_tools.
// A program that only renders to memory includes "volref_core.h" and links volref::volref_core.
// See README.md and docs/architecture.md.
#pragma once
#include "volref_core.h"
#include "core/film/ImageWriter.h"
