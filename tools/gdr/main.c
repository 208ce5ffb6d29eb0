/* gdr: the command-line program. It only parses arguments and calls the library. */
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "view.h"
#include "gdr/gdr.h"

static void print_help(FILE *out)
{
    fprintf(out, "gdr - a GPU-driven renderer on Vulkan\n"
          "\n"
          "usage:\n"
          "  gdr render SCENE [options]   render SCENE headless; print statistics\n"
          "  gdr view SCENE [options]     the scene in a window: fly through it, switch views, watch culling\n"
          "  gdr bench [options]          render the demo scene at several sizes; print a table and JSON\n"
          "  gdr build INPUT -o OUT.gdrc [--pvs] [--pvs-cell M]   import INPUT and write the processed-scene\n"
          "                               cache (--pvs: bake the precomputed visibility into it, in cells of\n"
          "                               M metres)\n"
          "  gdr info FILE                summarise a scene: meshes, instances, triangles, materials, ...\n"
          "  gdr info --passes            the passes, resources and barriers of every frame configuration\n"
          "  gdr cache list|clear [--cache-dir DIR]   the caches gdr keeps in its cache folder\n"
          "  gdr --help | --version\n"
          "\n"
          "SCENE is a .gltf, .glb, .obj or .gdrc file, or a built-in procedural scene:\n"
          "  demo[:instances=N,seed=S,spacing=M,textures=0|1]   objects on a ground grid (default\n"
          "                          10000); textures=1: generated textured materials\n"
          "  lod-field[:instances=N,seed=S,triangles=T,spacing=M]   N copies (default 1000) of one\n"
          "                          dense closed mesh of about T triangles (default 100000), near to far\n"
          "  occlusion[:seed=S,hidden=N,visible=N]    a wall of buildings in front of N hidden objects\n"
          "                          (default 4000), N visible ones in front (default 300), gaps\n"
          "  unique-field[:meshes=M,seed=S,triangles=T,spacing=M]   M different dense meshes (default\n"
          "                          100) of about T triangles (default 100000), one copy each\n"
          "  rooms[:rooms=N,seed=S,objects=K]   N rooms (default 16) joined into a maze by corridors,\n"
          "                          K props in each (default 24): walls hide most rooms (for --pvs)\n"
          "Source files go through a .gdrc cache in $XDG_CACHE_HOME/gdr (else ~/.cache/gdr), keyed by the\n"
          "source's absolute path and checked against every file its import looked for.\n"
          "\n"
          "render options:\n"
          "  --out FILE.png          write the last frame's image\n"
          "  --stats FILE.json       write the statistics as JSON\n"
          "  --width W --height H    render target size (default 1280x720)\n"
          "  --camera px,py,pz,qx,qy,qz,qw   camera position and rotation (identity looks down -Z)\n"
          "  --camera-index N        use the scene's camera N (default 0, or a camera framing the scene)\n"
          "  --cull on|off           culling at every level (default on; off draws everything)\n"
          "  --pipeline mesh|indirect|cpu   task/mesh shaders (default where available), compute cull +\n"
          "                          one indirect-count draw, or the CPU-driven baseline\n"
          "  --meshlet-cull on|off   cluster frustum culling (mesh pipeline; default on)\n"
          "  --cone-cull on|off      cluster normal-cone culling (mesh pipeline; default on)\n"
          "  --triangle-cull on|off  back-facing / sample-free triangle culling (mesh pipeline; default on)\n"
          "  --occlusion on|off      two-phase occlusion culling against the depth pyramid (default:\n"
          "                          on for the indirect pipeline, off for the mesh pipeline)\n"
          "  --raster hybrid|hw|sw|forward   how the mesh pipeline rasterises: visibility buffer from the\n"
          "                          compute rasteriser and/or mesh shaders, or forward shading (default\n"
          "                          hybrid where the device has 64-bit buffer atomics)\n"
          "  --sw-threshold PX       hybrid: clusters whose triangles are smaller go to compute (default 12)\n"
          "  --view shaded|meshlets|instances|triangles|overdraw|lod   what the image shows (lod: colour\n"
          "                          by LOD DAG depth)\n"
          "  --lod-error PIXELS      LOD cut: coarsest clusters whose projected error is within PIXELS\n"
          "                          (mesh pipeline; default 1, where the library's\n"
          "                          gdr_frame_desc.lod_error_px defaults to 0; 0 draws full detail)\n"
          "  --lod-depth N           draw the discrete cut at LOD DAG depth N instead (0: full detail)\n"
          "  --min-screen-size S     do not draw instances whose bounding sphere's screen size (about\n"
          "                          its projected diameter over the image height) is below S\n"
          "                          (GPU-driven and CPU pipelines; default 0: no minimum)\n"
          "  --clip-plane a,b,c,d    do not draw instances entirely on the negative side of the plane\n"
          "                          a x + b y + c z + d = 0 (world space; default: none)\n"
          "  --pvs on|off            cull instances the camera's precomputed-visibility cell does not\n"
          "                          list (a .gdrc written with gdr build --pvs; default on when it has one)\n"
          "  --lod-hierarchy on|off  find the cut by traversing each mesh's LOD hierarchy, or by testing\n"
          "                          every cluster of the DAG (the same cut; default on)\n"
          "  --point-level on|off    draw an instance whose whole mesh projects within a pixel as one\n"
          "                          splat, its point level (visibility buffer, LOD by error; default on)\n"
          "  --frames N              render N frames (timings are means over them; default 1)\n"
          "  --camera-path FILE      one frame per pose of a recorded path (gdr view --record-path;\n"
          "                          --frames N repeats it to N frames; docs/VIEWER.md)\n"
          "  --settle N              with --camera-path on a streamed scene: each pose drawn until no\n"
          "                          page is asked for, read or copied (at most N frames), its row the\n"
          "                          frame after: the converged frame at every pose\n"
          "  --warm-up N             N frames at the first pose (or the camera) before the frames\n"
          "                          measured, in no row or statistic: the GPU leaves its idle power\n"
          "                          state (default 0)\n"
          "  --geometry-budget MIB   stream the scene's geometry from its paged cache (a .gdrc written\n"
          "                          with gdr build --pages; a source or built-in scene gets one built in\n"
          "                          the cache folder) through a page pool of MIB mebibytes; the LOD\n"
          "                          threshold rises while a view needs more (default with --upload-budget:\n"
          "                          a quarter of the GPU's memory, at most 4096; docs/STREAMING.md)\n"
          "  --upload-budget MIB     streaming: bytes copied into the pool per frame at most (default 16)\n"
          "  --device N|NAME         Vulkan device by index or name substring (default: first discrete GPU)\n"
          "  --validate              enable the Khronos validation layer; messages are counted and\n"
          "                          make the exit status 3\n"
          "  --no-cache              import the source file, never read or write its .gdrc cache\n"
          "  --cache-dir DIR         keep caches in DIR instead of the per-user cache folder; '.': next\n"
          "                          to the source (SOURCE.gdrc)\n"
          "  --cache-max MIB         the cache folder's size limit: least recently used caches gdr wrote\n"
          "                          there are removed past it (default GDR_CACHE_MAX_MIB, else 4096)\n"
          "  --strict                every warning of the import (said again on cached runs) is an\n"
          "                          error: exit status 4 (render, view, info, build)\n"
          "  --budget KEY=N,...      limits for untrusted files (render, info, build): triangles,\n"
          "                          instances, pixels (texture pixels), bytes (decoded bytes);\n"
          "                          see docs/SECURITY.md for the defaults\n"
          "  --allow-outside-files   let a glTF name buffers and images outside its own folder\n"
          "                          (absolute paths, '..', links pointing out; default: refused)\n"
          "\n"
          "view options (and the render options above but --out, --stats and the two budgets):\n"
          "  --frames N              present N frames, then exit (default: until closed or Escape)\n"
          "  --screenshot FILE.png   write the last presented image (what the window shows)\n"
          "  --screenshot-dir DIR    where F12 writes gdr-view-NNNN.png (default .)\n"
          "  --record-path FILE      write the camera of every frame as a camera path\n"
          "  --camera-path FILE      fly the recorded path instead of the keys\n"
          "  --overlay on|off        statistics over the image (default on; TAB toggles it)\n"
          "  --no-vsync              present without waiting for the refresh (Y toggles it)\n"
          "  --max-fps N             at most N frames per second (default: as the present mode allows)\n"
          "  keys:\n"
          "%s"
          "\n"
          "bench options:\n"
          "  --sizes N,N,...         instance counts (default 1000,10000,100000,1000000)\n"
          "  --pipelines P,P,...     pipelines to run side by side (mesh, indirect, cpu; default: the default)\n"
          "  --scene SPEC            one scene (a file, 'demo:...', ...) instead of the demo at --sizes\n"
          "  --lod-errors E,E,...    LOD thresholds in pixels to run side by side (default 1; 0: full detail)\n"
          "  --occlusion on|off|on,off   occlusion culling, or both side by side (default: the\n"
          "                          pipeline's, as for render)\n"
          "  --lod-hierarchy on|off  the LOD hierarchy traversal (default on)\n"
          "  --point-level on|off    the point level of instances within a pixel (default on)\n"
          "  --frames N              frames per size (default 20)\n"
          "  --width W --height H    render target size (default 1920x1080)\n"
          "  --camera px,py,pz,qx,qy,qz,qw   instead of the demo camera\n"
          "  --record-every-frame    record the GPU-driven frames' commands every frame (default:\n"
          "                          once, then submitted again while nothing they depend on changes)\n"
          "  --camera-path FILE      time one frame per pose of the path (a row per frame)\n"
          "  --plot FILE.svg         plot GPU ms per pass against scene size, or per frame along\n"
          "                          --camera-path (needs gnuplot)\n"
          "  --plot-from FILE.json   with --plot: plot an earlier run's --json instead of running\n"
          "  --device N|NAME, --validate, --json FILE\n"
          "\n"
          "exit status: 0 success, 1 failure, 2 bad usage, 3 validation messages, 4 warnings under --strict\n",
          view_key_help);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        print_help(stderr);
        return 2;
    }
    const char *command = argv[1];
    if (strcmp(command, "--help") == 0 || strcmp(command, "-h") == 0 || strcmp(command, "help") == 0) {
        print_help(stdout);
        return 0;
    }
    if (strcmp(command, "--version") == 0) {
        printf("gdr %s\n", gdr_version());
        return 0;
    }
    if (strcmp(command, "render") == 0)
        return gdr_cmd_render(argc - 1, argv + 1);
    if (strcmp(command, "bench") == 0)
        return gdr_cmd_bench(argc - 1, argv + 1);
    if (strcmp(command, "build") == 0)
        return gdr_cmd_build(argc - 1, argv + 1);
    if (strcmp(command, "view") == 0)
        return gdr_cmd_view(argc - 1, argv + 1);
    if (strcmp(command, "info") == 0)
        return gdr_cmd_info(argc - 1, argv + 1);
    if (strcmp(command, "cache") == 0)
        return gdr_cmd_cache(argc - 1, argv + 1);
    fprintf(stderr, "gdr: unknown command '%s' (see gdr --help)\n", command);
    return 2;
}
