/*
 * The boot epoch of authenticated frames (PH_INTEGRITY_AUTH, docs/core.md "auth"):
 * kept in the Crazyflie's persistent storage (crazyflie-firmware
 * src/hal/interface/storage.h:65, 78) and incremented at every boot, so that the
 * counters of this boot's frames are larger than any a neighbour accepted before: a
 * rebooted drone is heard again from its first frame (the first frame after
 * ph_agent_set_boot_epoch carries the full counter).
 */
#pragma once

#include <stdbool.h>
#include <stdint.h>

/* The storage key of the epoch. */
#define FORMATION_EPOCH_KEY "phForm/epoch"

/* This boot's epoch: the stored one plus one (1 at the first boot), stored back
 * before it is used. false when the storage fails or the epochs are exhausted: the
 * app must then not send authenticated frames (they could repeat counters). */
bool formation_next_boot_epoch(uint32_t *epoch);
