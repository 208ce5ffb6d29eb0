/* gdr: a GPU-driven renderer on Vulkan. One include for the whole public API. */
#ifndef GDR_GDR_H
#define GDR_GDR_H

#include "gdr/core.h"
#include "gdr/geometry.h"
#include "gdr/math.h"
#include "gdr/renderer.h"
#include "gdr/scene.h"

#endif
