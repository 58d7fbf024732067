/* Every agent's configuration blob, indexed by wire id: ph_blobs[id] (NULL if the
   scenario has no agent id) is ph_blob_lens[id] bytes for ph_agent_init_blob().
   Written by `host-sim export --all` with ph_blobs.c; see docs/crazyflie.md. */
#pragma once

#include <stddef.h>
#include <stdint.h>

extern const uint8_t *const ph_blobs[];
extern const size_t ph_blob_lens[];
/* Entries of ph_blobs and ph_blob_lens (the largest id + 1). */
extern const size_t ph_blob_count;
