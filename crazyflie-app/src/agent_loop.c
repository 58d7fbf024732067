/*
 * One formation agent's per-tick logic (agent_loop.h).
 */
#include "agent_loop.h"

ph_status agent_loop_init(agent_loop *loop, uint8_t *memory, size_t size, uint8_t id,
                          ph_config *scratch)
{
    __builtin_memset(loop, 0, sizeof *loop);
    loop->agent = (ph_agent *)memory;
    loop->id = id;
    loop->first = true;
#ifdef FORMATION_USE_STRUCT
    ph_status s = formation_config(id, scratch);
    if (s == PH_OK)
        s = ph_agent_init(loop->agent, size, scratch);
#else
    (void)scratch;
    const uint8_t *blob = NULL;
    size_t len = 0;
    ph_status s = formation_blob(id, &blob, &len);
    if (s == PH_OK)
        s = ph_agent_init_blob(loop->agent, size, blob, len);
#endif
    if (s == PH_OK)
        s = ph_actuator_init(&loop->actuator, loop->agent, FORMATION_MASS, FORMATION_MAX_SPEED,
                             FORMATION_LEAD);
    if (s == PH_OK)
        s = ph_actuator_set_second_lead(&loop->actuator, FORMATION_SECOND_LEAD);
    if (s == PH_OK)
        s = ph_actuator_set_jerk_filter(&loop->actuator, FORMATION_JERK_FILTER);
    if (s == PH_OK && FORMATION_MAX_GAP > 0.0f)
        s = ph_actuator_set_max_gap(&loop->actuator, FORMATION_MAX_GAP);
    if (s == PH_OK)
        s = formation_state_init(&loop->formation, loop->agent);
    return s;
}

void agent_loop_receive(agent_loop *loop, uint8_t port, const uint8_t *bytes, size_t len,
                        uint32_t now_ms)
{
    if (port == AGENT_LOOP_FRAME_PORT)
        (void)ph_receive(loop->agent, bytes, len); /* rejections: ph_stats() */
    else if (port == FORMATION_POSITION_PORT)
        (void)formation_position_received(&loop->formation, loop->agent, bytes, len, now_ms);
}

typedef struct {
    agent_loop_send_fn send;
    void *ctx;
} frame_sink;

/* ph_send_fn: one formation frame to the P2P broadcast. */
static void send_frame(void *ctx, const uint8_t *bytes, size_t len)
{
    const frame_sink *sink = ctx;
    sink->send(sink->ctx, AGENT_LOOP_FRAME_PORT, bytes, len);
}

ph_status agent_loop_set_boot_epoch(agent_loop *loop, uint32_t epoch)
{
    loop->position_counter = (uint64_t)epoch << 32;
    return ph_agent_set_boot_epoch(loop->agent, epoch);
}

void agent_loop_restart(agent_loop *loop, uint32_t now_ms, bool new_origin)
{
    loop->actuator.has_command = 0; /* the next ph_actuate starts from the velocity */
    if (new_origin)
        loop->origin_ms = now_ms;
}

ph_status agent_loop_tick(agent_loop *loop, uint32_t now_ms, agent_loop_send_fn send,
                          void *ctx)
{
    ph_bearing bearings[PH_MAX_NEIGHBOURS];
    float position[2];
    ph_measurements m = {0};
    if (loop->first)
        loop->origin_ms = now_ms;
    /* Differences modulo 2^32: right across the clock's wrap. */
    m.time = (float)(uint32_t)(now_ms - loop->origin_ms) / 1000.0f;
    m.dt = loop->first ? 0.0f : (float)(uint32_t)(now_ms - loop->previous_ms) / 1000.0f;
    loop->previous_ms = now_ms;
    formation_expire(&loop->formation, now_ms);
    formation_read_velocity(m.velocity);
    formation_read_position(position);
    m.bearings = bearings;
    m.bearing_count =
        formation_read_bearings(&loop->formation, position, now_ms, bearings, PH_MAX_NEIGHBOURS);
    m.has_partner_offset =
        formation_read_partner_offset(&loop->formation, position, now_ms, m.partner_offset) ? 1u
                                                                                          : 0u;

    /* A refused call (a bug here) leaves out as a zero, safe force: still apply it. */
    loop->status = ph_step(loop->agent, &m, &loop->out);
    if (loop->out.status != PH_OUTPUT_NOMINAL && !loop->first)
        loop->safe_ticks++;

    /* The velocity setpoint: S1 integrated by the core (ph_actuate); the first tick,
     * and a safe output that has lasted the neighbour timeout (the actuator's stall
     * limit), start from the measured velocity (SPEC S21c: the safe force damps the
     * vehicle's own velocity, not a virtual one that ran ahead). Once per episode: at
     * every safe tick the setpoint would be the noisy measured velocity, a random walk;
     * on every isolated safe tick of a lossy channel, that noise too. */
    if (loop->out.status != PH_OUTPUT_SAFE) {
        loop->safe_s = 0.0f;
        loop->reseeded = false;
    } else {
        loop->safe_s += m.dt;
        if (!loop->reseeded && loop->safe_s >= loop->actuator.max_interval) {
            loop->actuator.has_command = 0;
            loop->reseeded = true;
        }
    }
    if (loop->first)
        loop->actuator.has_command = 0;
    if (ph_actuate(&loop->actuator, loop->out.force, m.velocity, m.dt, loop->setpoint) != PH_OK)
        loop->setpoint[0] = loop->setpoint[1] = 0.0f;

    frame_sink sink = {send, ctx};
    size_t frames = 0;
    (void)ph_frames_cb(loop->agent, send_frame, &sink, &frames);
    /* The position goes with the frames, at the configuration's communication rate
     * (comm_rate_hz: every tick by default), as host-sim sends it. */
    if (frames > 0) {
        uint8_t packet[FORMATION_POSITION_LEN];
        size_t n = formation_position_packet(loop->agent, position, loop->position_counter,
                                             packet, sizeof packet);
        loop->position_counter++;
        if (n > 0)
            send(ctx, FORMATION_POSITION_PORT, packet, n);
    }

    loop->first = false;
    loop->ticks++;
    return loop->status;
}
