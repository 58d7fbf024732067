/*
 * Argument and error handling of the C API, from C (`c-host-demo --checks`).
 * One line per check: "ok <what>" or "FAIL <what>: got <status>".
 */
#include <stdio.h>
#include <string.h>

#include "paper_demo.h"

static int failures;

static void expect(const char *what, ph_status got, ph_status want)
{
    if (got == want) {
        printf("ok %s: %s\n", what, ph_status_str(got));
    } else {
        printf("FAIL %s: got %s, want %s\n", what, ph_status_str(got), ph_status_str(want));
        failures++;
    }
}

static void expect_true(const char *what, int cond)
{
    printf("%s %s\n", cond ? "ok" : "FAIL", what);
    if (!cond)
        failures++;
}

static uint8_t mem[PH_AGENT_SIZE + PH_AGENT_ALIGN] __attribute__((aligned(PH_AGENT_ALIGN)));

int api_checks(void)
{
    ph_agent *a = (ph_agent *)mem;
    ph_config c;
    ph_output out;
    ph_measurements m = {0};
    size_t n = 99;

    expect_true("ph_status_str names codes",
                strcmp(ph_status_str(PH_ERR_BLOB_CHECKSUM), "PH_ERR_BLOB_CHECKSUM") == 0 &&
                    strcmp(ph_status_str(12345), "unknown status") == 0);
    expect("config_default NULL", ph_config_default(NULL, 1), PH_ERR_NULL);

    /* Memory never initialised (static, zeroed). */
    expect("step before init", ph_step(a, &m, &out), PH_ERR_NOT_INITIALIZED);
    expect_true("step before init: zero force, safe",
                out.force[0] == 0.0f && out.force[1] == 0.0f && out.status == PH_OUTPUT_SAFE &&
                    out.fault == PH_FAULT_NONE && out.fault_neighbour == -1);

    demo_paper_config(2, &c); /* agent 3 */
    expect("init NULL agent", ph_agent_init(NULL, PH_AGENT_SIZE, &c), PH_ERR_NULL);
    expect("init NULL config", ph_agent_init(a, PH_AGENT_SIZE, NULL), PH_ERR_NULL);
    expect("init small memory", ph_agent_init(a, PH_AGENT_SIZE - 1, &c), PH_ERR_STORAGE_SIZE);
    expect("init misaligned", ph_agent_init((ph_agent *)(mem + 1), PH_AGENT_SIZE, &c),
           PH_ERR_STORAGE_ALIGN);
    expect("init agent 3", ph_agent_init(a, PH_AGENT_SIZE, &c), PH_OK);

    uint8_t ids[PH_MAX_NEIGHBOURS];
    expect("neighbours", ph_neighbours(a, ids, PH_MAX_NEIGHBOURS, &n), PH_OK);
    expect_true("agent 3's neighbours are 1, 2, 4",
                n == 3 && ids[0] == 1 && ids[1] == 2 && ids[2] == 4);
    expect("neighbours, room for 1", ph_neighbours(a, ids, 1, &n), PH_ERR_BUFFER_FULL);
    expect_true("neighbours, room for 1: one written", n == 1 && ids[0] == 1);

    /* Frames. */
    uint8_t junk[PH_MAX_FRAME_LEN + 1] = {0};
    expect("receive empty", ph_receive(a, NULL, 0), PH_ERR_FRAME_TOO_SHORT);
    expect("receive NULL bytes", ph_receive(a, NULL, 5), PH_ERR_NULL);
    expect("receive 61 bytes", ph_receive(a, junk, sizeof junk), PH_ERR_FRAME_TOO_LONG);
    expect("receive zeros", ph_receive(a, junk, 20), PH_ERR_FRAME_BAD_CRC);
    ph_frame_stats st;
    expect("stats", ph_stats(a, &st), PH_OK);
    expect_true("stats count the rejected frames",
                st.accepted == 0 && st.bad_length == 2 && st.bad_crc == 1);

    /* Steps. */
    ph_bearing b[PH_MAX_NEIGHBOURS + 1];
    memset(b, 0, sizeof b);
    for (int k = 0; k < PH_MAX_NEIGHBOURS + 1; k++)
        b[k].direction[0] = 1.0f;
    m.bearings = b;
    m.bearing_count = PH_MAX_NEIGHBOURS + 1;
    expect("step with 13 bearings", ph_step(a, &m, &out), PH_ERR_ARGUMENT);
    m.bearing_count = 1;
    b[0].neighbour = 1;
    b[0].flags = 0x80;
    expect("step with unknown flag bits", ph_step(a, &m, &out), PH_ERR_ARGUMENT);
    b[0].flags = PH_BEARING_HAS_RATE;
    expect("step NULL out", ph_step(a, &m, NULL), PH_ERR_NULL);
    expect("step NULL measurements", ph_step(a, NULL, &out), PH_ERR_NULL);
    m.bearings = NULL;
    expect("step NULL bearings", ph_step(a, &m, &out), PH_ERR_NULL);
    m.bearings = b;
    b[0].neighbour = 9;
    m.velocity[0] = 2.0f;
    expect("step with a bearing to a stranger", ph_step(a, &m, &out), PH_OK);
    expect_true("... is the safe output, fault UNKNOWN_NEIGHBOUR 9",
                out.status == PH_OUTPUT_SAFE && out.fault == PH_FAULT_UNKNOWN_NEIGHBOUR &&
                    out.fault_neighbour == 9 && out.force[0] == -2.0f && out.force[1] == 0.0f);
    m.bearing_count = 0;
    expect("step hearing nobody", ph_step(a, &m, &out), PH_OK);
    expect_true("... is the safe output, fault STALE",
                out.status == PH_OUTPUT_SAFE && out.fault == PH_FAULT_STALE);

    uint8_t frames[PH_MAX_FRAMES_PER_TICK][PH_MAX_FRAME_LEN];
    uint8_t lens[PH_MAX_FRAMES_PER_TICK];
    expect("frames into no room", ph_frames(a, frames, lens, 0, &n), PH_ERR_BUFFER_FULL);
    expect_true("... none written", n == 0);
    expect("frames", ph_frames(a, frames, lens, PH_MAX_FRAMES_PER_TICK, &n), PH_OK);
    expect_true("... one frame of at most 60 bytes", n == 1 && lens[0] > 0 && lens[0] <= 60);
    expect("frames_cb NULL callback", ph_frames_cb(a, NULL, NULL, &n), PH_ERR_NULL);

    /* Configurations the core refuses; a failed init leaves no agent. */
    c.triangles[0].vertices[2] = 4; /* {1, 2, 4}: no agent 3 */
    expect("init triangle without me", ph_agent_init(a, PH_AGENT_SIZE, &c),
           PH_ERR_CONFIG_NOT_IN_TRIANGLE);
    expect("step after failed init", ph_step(a, &m, &out), PH_ERR_NOT_INITIALIZED);
    demo_paper_config(2, &c);
    c.triangle_count = PH_MAX_TRIANGLES + 1;
    expect("init 9 triangles", ph_agent_init(a, PH_AGENT_SIZE, &c),
           PH_ERR_CONFIG_TOO_MANY_TRIANGLES);
    demo_paper_config(2, &c);
    c.estimator = 7;
    expect("init estimator 7", ph_agent_init(a, PH_AGENT_SIZE, &c), PH_ERR_CONFIG_BAD_ENUM);
    demo_paper_config(2, &c);
    c.triangles[1].angles[0].cos_desired = -0.9f; /* 154 + 45 deg >= 180 */
    expect("init infeasible angles", ph_agent_init(a, PH_AGENT_SIZE, &c),
           PH_ERR_CONFIG_INFEASIBLE_ANGLES);
    demo_paper_config(2, &c);
    c.limits.max_force = -1.0f;
    expect("init negative max_force", ph_agent_init(a, PH_AGENT_SIZE, &c),
           PH_ERR_CONFIG_BAD_PARAMETER);

    /* Blobs (the encoder is Rust: tests/c_host.rs feeds good ones). */
    const uint8_t not_a_blob[16] = "NOPE, NOT A BLOB";
    expect("init_blob NULL", ph_agent_init_blob(a, PH_AGENT_SIZE, NULL, 0), PH_ERR_NULL);
    expect("init_blob bad magic", ph_agent_init_blob(a, PH_AGENT_SIZE, not_a_blob, 16),
           PH_ERR_BLOB_MAGIC);

    printf("checks: %d failed\n", failures);
    return failures == 0;
}
