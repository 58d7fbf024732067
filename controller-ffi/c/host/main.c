/*
 * Host test program of the C API (built and run by controller-ffi/tests/c_host.rs).
 *
 *   c-host-demo                       paper demo, agents from C structs
 *   c-host-demo --blob F1 F2 F3 F4    paper demo, agent i from blob file Fi
 *   c-host-demo --checks              argument and error handling of the API
 *   c-host-demo --dump-configs DIR    writes DIR/config<i>.bin, the raw ph_config of
 *                                     agent i (the Rust test turns them into blobs)
 *
 * Prints the DEMO lines of paper_demo.h (or one line per check); exits 0 when
 * the demo converged (or every check passed), 1 otherwise, 2 on usage errors.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "paper_demo.h"

void demo_out(const char *text)
{
    fputs(text, stdout);
}

/* The agents' memory: static, as on a microcontroller. */
static uint8_t memory[DEMO_N][PH_AGENT_SIZE] __attribute__((aligned(PH_AGENT_ALIGN)));

static int read_file(const char *path, uint8_t *buf, size_t cap, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        fprintf(stderr, "cannot open %s\n", path);
        return 0;
    }
    *len = fread(buf, 1, cap, f);
    int ok = !ferror(f) && feof(f);
    fclose(f);
    if (!ok)
        fprintf(stderr, "cannot read %s (or longer than %zu bytes)\n", path, cap);
    return ok;
}

int api_checks(void); /* checks.c */

static int dump_configs(const char *dir)
{
    for (int i = 0; i < DEMO_N; i++) {
        char path[4096];
        snprintf(path, sizeof path, "%s/config%d.bin", dir, i + 1);
        ph_config config;
        memset(&config, 0, sizeof config); /* padding too: deterministic bytes */
        demo_paper_config(i, &config);
        FILE *f = fopen(path, "wb");
        if (!f || fwrite(&config, sizeof config, 1, f) != 1 || fclose(f) != 0) {
            fprintf(stderr, "cannot write %s\n", path);
            return 0;
        }
    }
    return 1;
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--checks") == 0)
        return api_checks() ? 0 : 1;
    if (argc == 3 && strcmp(argv[1], "--dump-configs") == 0)
        return dump_configs(argv[2]) ? 0 : 1;
    int blobs = argc == 6 && strcmp(argv[1], "--blob") == 0;
    if (argc != 1 && !blobs) {
        fprintf(stderr, "usage: %s [--blob F1 F2 F3 F4 | --checks | --dump-configs DIR]\n",
                argv[0]);
        return 2;
    }
    if (ph_abi_version() != PH_ABI_VERSION || ph_agent_size() != PH_AGENT_SIZE ||
        ph_agent_align() != PH_AGENT_ALIGN) {
        fprintf(stderr, "ph_formation.h does not match the linked library\n");
        return 1;
    }
    ph_agent *agents[DEMO_N];
    for (int i = 0; i < DEMO_N; i++) {
        agents[i] = (ph_agent *)memory[i];
        ph_status s;
        if (blobs) {
            uint8_t blob[PH_MAX_BLOB_LEN];
            size_t len = 0;
            if (!read_file(argv[2 + i], blob, sizeof blob, &len))
                return 1;
            s = ph_agent_init_blob(agents[i], sizeof memory[i], blob, len);
        } else {
            ph_config config;
            demo_paper_config(i, &config);
            s = ph_agent_init(agents[i], sizeof memory[i], &config);
        }
        if (s != PH_OK) {
            fprintf(stderr, "agent %d: %s\n", i + 1, ph_status_str(s));
            return 1;
        }
    }
    demo_result r;
    demo_run(agents, NULL, &r);
    demo_print(&r);

    ph_frame_stats st;
    ph_estimate est[PH_MAX_OWNED_ESTIMATES];
    for (int i = 0; i < DEMO_N; i++) {
        size_t n = 0;
        if (ph_stats(agents[i], &st) != PH_OK ||
            ph_owned_estimates(agents[i], est, PH_MAX_OWNED_ESTIMATES, &n) != PH_OK) {
            fprintf(stderr, "agent %d: ph_stats/ph_owned_estimates failed\n", i + 1);
            return 1;
        }
        printf("agent %d frames accepted=%u unknown_sender=%u rejected_other=%u estimates=", i + 1,
               (unsigned)st.accepted, (unsigned)st.unknown_sender,
               (unsigned)(st.bad_length + st.bad_crc + st.unknown_version + st.malformed +
                          st.stale + st.invalid_value));
        for (size_t k = 0; k < n; k++)
            printf("%s%u-%u:%.6f", k ? "," : "", (unsigned)est[k].apex, (unsigned)est[k].far,
                   (double)est[k].value);
        printf("\n");
    }
    return r.converged ? 0 : 1;
}
