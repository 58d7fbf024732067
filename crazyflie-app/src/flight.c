/*
 * The app's flight states (flight.h).
 */
#include "flight.h"

void flight_init(flight *f)
{
    __builtin_memset(f, 0, sizeof *f);
    f->state = FLIGHT_IDLE;
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

static bool outside_fence(const flight_policy *p, const float q[2])
{
    for (int k = 0; k < 2; k++)
        if (!(q[k] >= p->fence_min[k] && q[k] <= p->fence_max[k]))
            return true; /* NaN is outside */
    return false;
}

/* Battery low for vbat_ms (the voltage sags under load: a short dip is no reason). */
static bool battery_low(flight *f, const flight_policy *p, const flight_inputs *in)
{
    if (!(p->vbat_land > 0.0f) || !(in->vbat < p->vbat_land)) {
        f->low = false;
        return false;
    }
    if (!f->low) {
        f->low = true;
        f->low_ms = in->now_ms;
    }
    return (uint32_t)(in->now_ms - f->low_ms) >= p->vbat_ms;
}

flight_action flight_update(flight *f, const flight_policy *p, const flight_inputs *in)
{
    bool rising = in->enable && !f->last_enable;
    f->last_enable = in->enable;
    f->restart = false;
    bool low = battery_low(f, p, in);

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
        return enter(f, FLIGHT_FORMATION, FLIGHT_FAULT_NONE, FLIGHT_ACT_SETPOINT);
    case FLIGHT_FORMATION:
    case FLIGHT_HOLD:
        if (!in->enable)
            return enter(f, FLIGHT_IDLE, FLIGHT_FAULT_NONE, FLIGHT_ACT_RELEASE);
        if (!in->positioning)
            return enter(f, FLIGHT_LANDING, FLIGHT_FAULT_POSITIONING, FLIGHT_ACT_LAND);
        if (outside_fence(p, in->position))
            return enter(f, FLIGHT_LANDING, FLIGHT_FAULT_FENCE, FLIGHT_ACT_LAND);
        if (low)
            return enter(f, FLIGHT_LANDING, FLIGHT_FAULT_BATTERY, FLIGHT_ACT_LAND);
        if (f->state == FLIGHT_FORMATION) {
            if (!in->controller_safe)
                return FLIGHT_ACT_SETPOINT;
            f->since_ms = in->now_ms;
            f->hold[0] = in->position[0];
            f->hold[1] = in->position[1];
            return enter(f, FLIGHT_HOLD, FLIGHT_FAULT_LOST, FLIGHT_ACT_HOLD);
        }
        if (!in->controller_safe) {
            f->restart = true;
            return enter(f, FLIGHT_FORMATION, FLIGHT_FAULT_NONE, FLIGHT_ACT_SETPOINT);
        }
        if ((uint32_t)(in->now_ms - f->since_ms) >= p->hold_timeout_ms)
            return enter(f, FLIGHT_LANDING, FLIGHT_FAULT_LOST_TIMEOUT, FLIGHT_ACT_LAND);
        return FLIGHT_ACT_HOLD;
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
    };
    return (unsigned)f < sizeof names / sizeof names[0] ? names[f] : "?";
}
