/*
 * qemu-insn: a QEMU TCG plugin that counts guest instructions executed
 * inside marked regions.
 *
 * The firmware owns a table of 32-bit words (symbol PH_INSN_MARKERS in
 * firmware-example/src/measure.rs). A store to word 2*id begins region `id`,
 * a store to word 2*id+1 ends it. For every end, the plugin prints
 *
 *     qemu-insn region=<id> seq=<k> insns=<n>
 *
 * where <n> counts the instructions that executed after the begin store up
 * to and including the end store, and <k> numbers the occurrences of that id
 * (0, 1, …). At exit it prints `qemu-insn total=<all executed instructions>`.
 *
 * Arguments (-plugin libqemu-insn.so,marker=0x20000000,regions=64,out=FILE):
 *   marker=ADDR   address of the marker table (required; hex or decimal)
 *   regions=N     number of region ids in the table (default 64, the firmware's MAX_REGIONS)
 *   out=FILE      write the lines to FILE instead of QEMU's log (stderr)
 *   profile=ID    also count, per instruction address, the instructions
 *                 executed inside region ID (all its occurrences), and print
 *                 `qemu-insn profile pc=0x<addr> insns=<n>` lines at exit
 *                 (cargo xtask firmware-profile maps them to functions)
 *
 * Counting uses one callback per executed instruction, so the count is exact
 * and independent of how QEMU splits code into translation blocks. It
 * assumes one vCPU (true for the Cortex-M machines).
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "qemu-plugin-api.h"

#ifndef QEMU_INSN_API_VERSION
#error "build with -DQEMU_INSN_API_VERSION=<plugin API version> (see build.sh)"
#endif

QEMU_PLUGIN_EXPORT int qemu_plugin_version = QEMU_INSN_API_VERSION;

#define MAX_REGIONS_LIMIT 1024

static uint64_t marker_base;
static uint64_t n_regions = 64;
static FILE *out_file;

static uint64_t executed;                       /* all instructions so far */
static uint64_t begin_at[MAX_REGIONS_LIMIT];    /* `executed` at the begin store */
static uint64_t occurrences[MAX_REGIONS_LIMIT]; /* completed regions per id */
static unsigned char open_region[MAX_REGIONS_LIMIT];
static uint64_t errors;

/* Optional per-address profile of one region (open addressing, pc -> count). */
#define PROFILE_SLOTS (1u << 16)
static int64_t profile_region = -1;
static uint64_t profile_pc[PROFILE_SLOTS];
static uint64_t profile_count[PROFILE_SLOTS];
static uint64_t profile_dropped;

static void emit(const char *line)
{
    if (out_file) {
        fputs(line, out_file);
        fflush(out_file);
    } else {
        qemu_plugin_outs(line);
    }
}

static void on_insn(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    (void)userdata;
    executed++;
}

static void on_insn_profiled(unsigned int vcpu_index, void *userdata)
{
    (void)vcpu_index;
    executed++;
    if (!open_region[profile_region]) {
        return;
    }
    uint64_t pc = (uint64_t)(uintptr_t)userdata;
    uint32_t h = (uint32_t)((pc >> 1) * 2654435761u) & (PROFILE_SLOTS - 1);
    for (uint32_t i = 0; i < PROFILE_SLOTS; i++) {
        uint32_t slot = (h + i) & (PROFILE_SLOTS - 1);
        if (profile_count[slot] == 0 || profile_pc[slot] == pc) {
            profile_pc[slot] = pc;
            profile_count[slot]++;
            return;
        }
    }
    profile_dropped++;
}

static void on_mem(unsigned int vcpu_index, qemu_plugin_meminfo_t info, uint64_t vaddr, void *userdata)
{
    (void)vcpu_index;
    (void)userdata;
    if (!qemu_plugin_mem_is_store(info) || vaddr < marker_base) {
        return;
    }
    uint64_t off = vaddr - marker_base;
    if (off >= 8 * n_regions || off % 4 != 0) {
        return;
    }
    unsigned id = (unsigned)(off / 8);
    char line[160];
    if (off % 8 == 0) {
        if (open_region[id]) {
            snprintf(line, sizeof line, "qemu-insn error: region=%u begun twice without end\n", id);
            emit(line);
            errors++;
        }
        open_region[id] = 1;
        begin_at[id] = executed;
    } else if (!open_region[id]) {
        snprintf(line, sizeof line, "qemu-insn error: region=%u ended without begin\n", id);
        emit(line);
        errors++;
    } else {
        open_region[id] = 0;
        snprintf(line, sizeof line, "qemu-insn region=%u seq=%" PRIu64 " insns=%" PRIu64 "\n", id,
                 occurrences[id]++, executed - begin_at[id]);
        emit(line);
    }
}

static void on_translate(qemu_plugin_id_t id, struct qemu_plugin_tb *tb)
{
    (void)id;
    size_t n = qemu_plugin_tb_n_insns(tb);
    for (size_t i = 0; i < n; i++) {
        struct qemu_plugin_insn *insn = qemu_plugin_tb_get_insn(tb, i);
        if (profile_region >= 0) {
            void *pc = (void *)(uintptr_t)qemu_plugin_insn_vaddr(insn);
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_insn_profiled, QEMU_PLUGIN_CB_NO_REGS, pc);
        } else {
            qemu_plugin_register_vcpu_insn_exec_cb(insn, on_insn, QEMU_PLUGIN_CB_NO_REGS, NULL);
        }
        qemu_plugin_register_vcpu_mem_cb(insn, on_mem, QEMU_PLUGIN_CB_NO_REGS, QEMU_PLUGIN_MEM_W, NULL);
    }
}

static void on_plugin_exit(qemu_plugin_id_t id, void *userdata)
{
    (void)id;
    (void)userdata;
    char line[160];
    for (uint64_t r = 0; r < n_regions; r++) {
        if (open_region[r]) {
            snprintf(line, sizeof line, "qemu-insn error: region=%" PRIu64 " never ended\n", r);
            emit(line);
        }
    }
    if (profile_region >= 0) {
        for (uint32_t i = 0; i < PROFILE_SLOTS; i++) {
            if (profile_count[i]) {
                snprintf(line, sizeof line, "qemu-insn profile pc=0x%" PRIx64 " insns=%" PRIu64 "\n", profile_pc[i],
                         profile_count[i]);
                emit(line);
            }
        }
        snprintf(line, sizeof line, "qemu-insn profile region=%" PRId64 " dropped=%" PRIu64 "\n", profile_region,
                 profile_dropped);
        emit(line);
    }
    snprintf(line, sizeof line, "qemu-insn total=%" PRIu64 " errors=%" PRIu64 "\n", executed, errors);
    emit(line);
    if (out_file) {
        fclose(out_file);
        out_file = NULL;
    }
}

static int parse_u64(const char *s, uint64_t *v)
{
    char *end;
    unsigned long long x = strtoull(s, &end, 0);
    if (*s == '\0' || *end != '\0') {
        return -1;
    }
    *v = x;
    return 0;
}

QEMU_PLUGIN_EXPORT int qemu_plugin_install(qemu_plugin_id_t id, const qemu_info_t *info, int argc, char **argv)
{
    int have_marker = 0;
    const char *out_path = NULL;
    uint64_t profile_id = 0;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (strncmp(a, "marker=", 7) == 0 && parse_u64(a + 7, &marker_base) == 0) {
            have_marker = 1;
        } else if (strncmp(a, "regions=", 8) == 0 && parse_u64(a + 8, &n_regions) == 0 && n_regions > 0 &&
                   n_regions <= MAX_REGIONS_LIMIT) {
            /* parsed */
        } else if (strncmp(a, "out=", 4) == 0 && a[4] != '\0') {
            out_path = a + 4;
        } else if (strncmp(a, "profile=", 8) == 0 && parse_u64(a + 8, &profile_id) == 0) {
            profile_region = (int64_t)profile_id;
        } else {
            fprintf(stderr, "qemu-insn: bad argument '%s' (expected marker=ADDR, regions=N, out=FILE, profile=ID)\n", a);
            return -1;
        }
    }
    if (!have_marker) {
        fprintf(stderr, "qemu-insn: missing marker=ADDR (address of PH_INSN_MARKERS)\n");
        return -1;
    }
    if (profile_region >= (int64_t)n_regions) {
        fprintf(stderr, "qemu-insn: profile=%" PRId64 " is not a region id (regions=%" PRIu64 ")\n", profile_region,
                n_regions);
        return -1;
    }
    if (info->system_emulation && info->system.max_vcpus > 1) {
        fprintf(stderr, "qemu-insn: more than one vCPU; counts would mix CPUs\n");
        return -1;
    }
    if (out_path) {
        out_file = fopen(out_path, "w");
        if (!out_file) {
            perror("qemu-insn: opening out file");
            return -1;
        }
    }
    qemu_plugin_register_vcpu_tb_trans_cb(id, on_translate);
    qemu_plugin_register_atexit_cb(id, on_plugin_exit, NULL);
    return 0;
}
