/*
 * The app's flight states (flight.h).
 */
#include "flight.h"

void flight_init(flight *f)
{
    __builtin_memset(f, 0, sizeof *f);
    f->state = FLIGHT_IDLE;
    (void)ph_policy_init(&f->policy);
}

static flight_action enter(flight *f, flight_state s, flight_fault why, flight_action act)
{
    if (f->state != s)
        f->transitions++;
    f->state = s;
    f->fault = why;
    return act;
}

/* The pre-flight checks of a rising edge of enable (FLIGHT_FAULT_NONE: passed). */
static flight_fault preflight(const flight_policy *p, const flight_inputs *in)
{
    if (!in->flying)
        return FLIGHT_REFUSED_NOT_FLYING;
    if (!in->positioning)
        return FLIGHT_REFUSED_POSITIONING;
    if (in->heard < in->neighbours)
        return FLIGHT_REFUSED_NEIGHBOURS;
    float dx = in->position[0] - p->start[0], dy = in->position[1] - p->start[1];
    if (!(dx * dx + dy * dy <= p->start_tolerance * p->start_tolerance))
        return FLIGHT_REFUSED_AWAY;
    return FLIGHT_FAULT_NONE;
}

/* The landing fault of a policy reason. */
static flight_fault landing_fault(ph_policy_reason why)
{
    switch (why) {
    case PH_POLICY_FENCE: return FLIGHT_FAULT_FENCE;
    case PH_POLICY_BATTERY: return FLIGHT_FAULT_BATTERY;
    case PH_POLICY_POSITIONING: return FLIGHT_FAULT_POSITIONING;
    default: return FLIGHT_FAULT_LOST_TIMEOUT;
    }
}

flight_action flight_update(flight *f, const flight_policy *p, const flight_inputs *in)
{
    bool rising = in->enable && !f->last_enable;
    f->last_enable = in->enable;
    f->restart = false;
    uint32_t dt_ms = (uint32_t)(in->now_ms - f->last_ms); /* modulo 2^32 */
    f->last_ms = in->now_ms;

    /* The supervisor always wins. */
    if (!in->flying && f->state != FLIGHT_IDLE) {
        /* A landing ends here (landed): its reason stays in `fault`. */
        flight_fault why = f->state == FLIGHT_LANDING ? f->fault : FLIGHT_FAULT_SUPERVISOR;
        return enter(f, FLIGHT_IDLE, why, FLIGHT_ACT_RELAX);
    }

    switch (f->state) {
    case FLIGHT_IDLE:
        if (!rising)
            return FLIGHT_ACT_NONE;
        {
            flight_fault why = preflight(p, in);
            if (why != FLIGHT_FAULT_NONE) {
                f->refusals++;
                f->fault = why;
                return FLIGHT_ACT_NONE;
            }
        }
        f->restart = true;
        (void)ph_policy_reset(&f->policy); /* a new flight: the policies' timers at 0 */
        f->last_ms = in->now_ms;
        return enter(f, FLIGHT_FORMATION, FLIGHT_FAULT_NONE, FLIGHT_ACT_SETPOINT);
    case FLIGHT_FORMATION:
    case FLIGHT_HOLD: {
        if (!in->enable)
            return enter(f, FLIGHT_IDLE, FLIGHT_FAULT_NONE, FLIGHT_ACT_RELEASE);
        ph_policy_input pi = {
            .dt_ms = dt_ms,
            .lost = in->controller_safe ? 1u : 0u,
            .positioning = in->positioning ? 1u : 0u,
            .position = {in->position[0], in->position[1]},
            .battery = in->vbat,
        };
        ph_policy_action act = PH_POLICY_LAND;
        ph_policy_reason why = PH_POLICY_NONE;
        if (ph_policy_update(&f->policy, &p->core, &pi, &act, &why) != PH_OK)
            return enter(f, FLIGHT_LANDING, FLIGHT_FAULT_SETTINGS, FLIGHT_ACT_LAND);
        if (act == PH_POLICY_LAND)
            return enter(f, FLIGHT_LANDING, landing_fault(why), FLIGHT_ACT_LAND);
        if (act == PH_POLICY_HOLD) {
            if (f->state == FLIGHT_FORMATION) {
                f->hold[0] = in->position[0];
                f->hold[1] = in->position[1];
            }
            return enter(f, FLIGHT_HOLD, FLIGHT_FAULT_LOST, FLIGHT_ACT_HOLD);
        }
        if (f->state == FLIGHT_HOLD)
            f->restart = true;
        return enter(f, FLIGHT_FORMATION, FLIGHT_FAULT_NONE, FLIGHT_ACT_SETPOINT);
    }
    case FLIGHT_LANDING:
    default:
        return FLIGHT_ACT_NONE; /* the high-level commander lands; the supervisor ends it */
    }
}

const char *flight_state_str(flight_state s)
{
    static const char *const names[] = {"idle", "formation", "hold", "landing"};
    return (unsigned)s < sizeof names / sizeof names[0] ? names[s] : "?";
}

const char *flight_fault_str(flight_fault f)
{
    static const char *const names[] = {
        "none",          "refused: not flying", "refused: positioning",
        "refused: neighbours not heard", "refused: away from the initial position",
        "supervisor",    "lost: holding",       "lost: landing",
        "fence: landing", "battery: landing",   "positioning lost: landing",
        "policy settings refused: landing",
    };
    return (unsigned)f < sizeof names / sizeof names[0] ? names[f] : "?";
}
