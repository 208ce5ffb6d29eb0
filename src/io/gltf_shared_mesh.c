/* Primitives that read the same accessors share one gdr mesh. A primitive's geometry is a function
 * of its mode and its indices, POSITION, NORMAL, TEXCOORD_0 and COLOR_0 accessors alone (its
 * material belongs to the instance), so a second primitive with the same six values is the same
 * mesh: it is converted, cleaned, and later given meshlets and a LOD DAG once, and each primitive
 * becomes an instance of it. Without this, one 20,000-triangle accessor named by 3,355 primitives
 * (a file of 520 KB) cost three minutes and 3.2 GB. An open-addressing table, grown at half full. */
#include <stdlib.h>
#include <string.h>

#include <xxhash.h>

#include "io/gltf_internal.h"

static size_t slot_of(const gltf_geometry_key *key, size_t capacity)
{
    return (size_t)XXH3_64bits(key->values, sizeof key->values) & (capacity - 1);
}

static int grow(gltf_shared_meshes *t)
{
    size_t capacity = t->capacity ? t->capacity * 2 : 64;
    gltf_shared_mesh *slots = calloc(capacity, sizeof *slots);
    if (!slots)
        return 0;
    for (size_t i = 0; i < t->capacity; i++) {
        if (!t->slots[i].used)
            continue;
        size_t s = slot_of(&t->slots[i].key, capacity);
        while (slots[s].used)
            s = (s + 1) & (capacity - 1);
        slots[s] = t->slots[i];
    }
    free(t->slots);
    t->slots = slots;
    t->capacity = capacity;
    return 1;
}

int gltf_shared_mesh_find(const gltf_shared_meshes *t, const gltf_geometry_key *key, uint32_t *mesh)
{
    if (!t->capacity)
        return 0;
    for (size_t s = slot_of(key, t->capacity); t->slots[s].used; s = (s + 1) & (t->capacity - 1))
        if (memcmp(t->slots[s].key.values, key->values, sizeof key->values) == 0) {
            *mesh = t->slots[s].mesh;
            return 1;
        }
    return 0;
}

int gltf_shared_mesh_add(gltf_shared_meshes *t, const gltf_geometry_key *key, uint32_t mesh)
{
    if ((t->count + 1) * 2 > t->capacity && !grow(t))
        return 0;
    size_t s = slot_of(key, t->capacity);
    while (t->slots[s].used)
        s = (s + 1) & (t->capacity - 1);
    t->slots[s] = (gltf_shared_mesh){*key, mesh, 1};
    t->count++;
    return 1;
}

void gltf_shared_meshes_free(gltf_shared_meshes *t)
{
    free(t->slots);
    *t = (gltf_shared_meshes){0};
}
