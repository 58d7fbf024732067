/*
 * The boot epoch in persistent storage (epoch.h).
 */
#include "epoch.h"

#include "storage.h"

bool formation_next_boot_epoch(uint32_t *epoch)
{
    uint32_t e = 0;
    if (storageFetch(FORMATION_EPOCH_KEY, &e, sizeof e) != sizeof e)
        e = 0; /* first boot (or an entry of another size: start over above 0) */
    if (e == UINT32_MAX)
        return false;
    e++;
    if (!storageStore(FORMATION_EPOCH_KEY, &e, sizeof e))
        return false;
    *epoch = e;
    return true;
}
