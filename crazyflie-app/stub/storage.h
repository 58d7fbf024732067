/* Stub of crazyflie-firmware src/hal/interface/storage.h (commit 2a18fc29, lines
 * 65, 78): key/buffer persistent storage. */
#pragma once

#include <stdbool.h>
#include <stddef.h>

bool storageStore(const char *key, const void *buffer, size_t length);
size_t storageFetch(const char *key, void *buffer, size_t length);
