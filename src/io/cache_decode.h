/* Decoding a cache's per-mesh records on several threads (cache_decode.c), for the sections whose
 * records a streamed open reads: the cluster records (CLDT) and the hierarchies (LODH). */
#ifndef GDR_IO_CACHE_DECODE_H
#define GDR_IO_CACHE_DECODE_H

#include <stdint.h>

#include "gdr/core.h"

/* Decodes mesh `mesh` (its own input bytes and its own output only: meshes run at once); on
 * failure, the message in err. */
typedef gdr_status cache_mesh_decode_fn(void *user, uint32_t mesh, gdr_error *err);

/* fn for every mesh of [0, count): on the calling thread, in order, stopping at the first failure,
 * where `work` (the records all the meshes hold) is small or one thread is set; else on a thread per
 * processor, every mesh decoded. Either way the result is the first failure in mesh order, with its
 * message in err (err untouched on success), so a damaged file is refused with the same message. */
gdr_status cache_decode_meshes(uint32_t count, uint64_t work, cache_mesh_decode_fn *fn, void *user, gdr_error *err);

/* Tests: the decoding threads (1: the calling thread alone, in order; 2 or more: that many, however
 * few the records; 0, the default: one per processor where the work is large), to compare a
 * parallel decode with the serial one. */
void cache_set_decode_threads(uint32_t threads);

#endif
