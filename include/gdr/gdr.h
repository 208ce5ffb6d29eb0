/* gdr: a GPU-driven renderer on Vulkan. One include for the whole public API, bottom layer first
 * (docs/ARCHITECTURE.md): every header this build installs; the optional modules' only when the
 * library holds them (gdr/config.h). */
#ifndef GDR_GDR_H
#define GDR_GDR_H

#include "gdr/config.h"
#include "gdr/core.h"
#include "gdr/thread_pool.h"
#include "gdr/math.h"
#include "gdr/scene.h"
#include "gdr/mesh_clusters.h"
#include "gdr/geometry.h"
#if GDR_HAVE_CULL
#include "gdr/cull.h"
#endif
#include "gdr/procedural.h"
#include "gdr/io.h"
#include "gdr/paged_cache.h"
#include "gdr/renderer.h"
#include "gdr/renderer_vulkan.h"
#if GDR_HAVE_PRESENT
#include "gdr/present.h"
#endif

#endif
