/*
 * The CRTP services of a simulated Crazyflie (serve_agent.h), each written from
 * crazyflie-firmware (commit 2a18fc29) and checked against what cflib 0.1.34 sends
 * (docs/crazyflie.md "Simulated Crazyflies over udp://" lists what is implemented):
 *
 *   port 15 link   (src/modules/src/crtpservice.c:41-43, 80-95): echo, source
 *                  ("Bitcraze Crazyflie", 30 bytes), sink; the null packet 0xFF
 *                  answered with itself (what cflib's udp scan probes).
 *   port 13 platform (src/modules/src/platformservice.c:192-210): protocol version
 *                  CRTP_PROTOCOL_VERSION 12 (src/modules/interface/crtp.h:33), firmware
 *                  version and device type name.
 *   port 4 memory  (cflib mem/__init__.py CMD_INFO_NBR): no memories.
 *   port 2 param   (src/modules/src/param_logic.c:279-326 TOC v2, 328-352 write,
 *                  400-416 read): every PARAM_GROUP of the program, read and write;
 *                  a write is echoed, a read-only one is not answered.
 *   port 5 log     (src/modules/src/log.c:264-318 TOC v2, 320-360 control, 560-580
 *                  data): every LOG_GROUP; blocks created, appended (v2), started
 *                  (period in 10 ms or, v2, in ms), stopped, deleted, reset; data
 *                  [block, 24-bit ms timestamp, values converted to the fetch type].
 *   port 3, 7 setpoints (src/modules/src/crtp_commander_rpyt.c, crtp_commander_generic.c:
 *                  66-95 stop, position, velocity world, hover; crtp_commander.c:91-97
 *                  notify stop) at COMMANDER_PRIORITY_CRTP. A zero setpoint (type
 *                  stop, or RPYT with zero thrust) stops the motors.
 *   port 8 high-level commander (src/modules/src/crtp_commander_high_level.c:133-144,
 *                  420-460): take-off 2, land 2, stop, go to (1 and 2).
 *   port 9 supervisor (src/modules/src/crtp_supervisor.c:136-150) and, legacy, port 6
 *                  (crtp_localization_service.c:320-330): the emergency stop.
 */
#include <errno.h>
#include <string.h>

#include "serve_agent.h"

#define PORT_CONSOLE 0u
#define PORT_PARAM 2u
#define PORT_RPYT 3u
#define PORT_MEM 4u
#define PORT_LOG 5u
#define PORT_GENERIC 7u
#define PORT_LOCALIZATION 6u
#define PORT_HL 8u
#define PORT_SUPERVISOR 9u
#define PORT_PLATFORM 13u
#define PORT_LINK 15u

#define CRTP_PROTOCOL_VERSION 12 /* crtp.h:33 */
#define LOG_MAX_BLOCKS 16        /* log.c:92 */
#define LOG_MAX_OPS 128          /* log.c:91 */
#define LOG_MAX_LEN 26           /* log.c:88 */

static void reply(const crtp_packet *in, const uint8_t *data, uint8_t size)
{
    crtp_packet p = {in->port, in->channel, size, {0}};
    memcpy(p.data, data, size);
    crtp_send(&p);
}

static void put16(uint8_t *d, uint16_t v)
{
    d[0] = (uint8_t)v;
    d[1] = (uint8_t)(v >> 8);
}

static void put32(uint8_t *d, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        d[k] = (uint8_t)(v >> (8 * k));
}

/* FNV-1a over a TOC's names and types: the TOC's CRC (cflib's cache key). */
static uint32_t fnv(uint32_t h, const char *s, uint8_t type)
{
    for (; *s; s++)
        h = (h ^ (uint8_t)*s) * 16777619u;
    return (h ^ type) * 16777619u;
}

/* ---- parameters ---- */

/* The idx-th variable (groups skipped) and its group. */
static struct param_s *param_at(uint16_t idx, const char **group)
{
    uint16_t n = 0;
    *group = "";
    for (struct param_s *p = _param_start; p < _param_stop; p++) {
        if (p->name == NULL)
            continue; /* padding between two files' tables (serve_sections.ld) */
        if (p->type & PARAM_GROUP) {
            *group = (p->type & PARAM_START) ? p->name : "";
            continue;
        }
        if (n++ == idx)
            return p;
    }
    return NULL;
}

static uint8_t param_size(const struct param_s *p)
{
    return (uint8_t)(1u << (p->type & PARAM_BYTES_MASK));
}

static void toc_info(const crtp_packet *in, uint16_t count, uint32_t crc, bool log)
{
    uint8_t d[9] = {3};
    put16(d + 1, count);
    put32(d + 3, crc);
    d[7] = LOG_MAX_BLOCKS;
    d[8] = LOG_MAX_OPS;
    reply(in, d, log ? 9 : 7);
}

static void toc_item(const crtp_packet *in, uint16_t id, uint8_t type, const char *group,
                     const char *name)
{
    uint8_t d[CRTP_MAX_DATA] = {2};
    size_t gl = strlen(group), nl = strlen(name);
    if (4 + gl + nl + 2 > CRTP_MAX_DATA) {
        reply(in, d, 1);
        return;
    }
    put16(d + 1, id);
    d[3] = type;
    memcpy(d + 4, group, gl + 1);
    memcpy(d + 4 + gl + 1, name, nl + 1);
    reply(in, d, (uint8_t)(4 + gl + nl + 2));
}

static void param_packet(const crtp_packet *in)
{
    const char *group;
    uint8_t d[CRTP_MAX_DATA];
    if (in->size < 1)
        return;
    if (in->channel == 0) { /* TOC */
        if (in->data[0] == 3) {
            uint16_t count = 0;
            uint32_t crc = 2166136261u;
            for (struct param_s *p = param_at(0, &group); p != NULL; p = param_at(++count, &group))
                crc = fnv(fnv(crc, group, 0), p->name, p->type);
            toc_info(in, count, crc, false);
        } else if (in->data[0] == 2 && in->size >= 3) {
            uint16_t id = (uint16_t)(in->data[1] | in->data[2] << 8);
            struct param_s *p = param_at(id, &group);
            if (p == NULL) {
                d[0] = 2;
                reply(in, d, 1);
            } else {
                toc_item(in, id, p->type, group, p->name);
            }
        }
        return;
    }
    if (in->size < 2)
        return;
    uint16_t id = (uint16_t)(in->data[0] | in->data[1] << 8);
    struct param_s *p = param_at(id, &group);
    if (in->channel == 1) { /* read: param_logic.c:400-416 */
        put16(d, id);
        if (p == NULL) {
            d[2] = ENOENT;
            reply(in, d, 3);
            return;
        }
        d[2] = 0;
        memcpy(d + 3, p->address, param_size(p));
        reply(in, d, (uint8_t)(3 + param_size(p)));
    } else if (in->channel == 2) { /* write: param_logic.c:328-352 */
        if (p == NULL) {
            put16(d, id);
            d[2] = ENOENT;
            reply(in, d, 3);
            return;
        }
        if ((p->type & PARAM_RONLY) || in->size < 2 + param_size(p))
            return;
        memcpy(p->address, in->data + 2, param_size(p));
        reply(in, in->data, in->size);
        if (p->callback)
            p->callback();
    }
}

/* ---- logging ---- */

static const struct log_s *log_at(uint16_t idx, const char **group)
{
    uint16_t n = 0;
    *group = "";
    for (const struct log_s *l = _log_start; l < _log_stop; l++) {
        if (l->name == NULL)
            continue; /* padding */
        if (l->type & LOG_GROUP) {
            *group = (l->type & LOG_START) ? l->name : "";
            continue;
        }
        if (n++ == idx)
            return l;
    }
    return NULL;
}

static const uint8_t type_len[9] = {0, 1, 2, 4, 1, 2, 4, 4, 2}; /* log.c typeLength */

typedef struct {
    const struct log_s *var;
    uint8_t fetch; /* the client's type */
} log_op;

typedef struct {
    int id; /* -1: free */
    uint32_t period_ms;
    uint32_t next_ms;
    bool started;
    uint8_t n;
    log_op ops[LOG_MAX_LEN];
} log_block;

static log_block blocks[LOG_MAX_BLOCKS];
static bool blocks_ready;

static void log_reset(void)
{
    memset(blocks, 0, sizeof blocks);
    for (int k = 0; k < LOG_MAX_BLOCKS; k++)
        blocks[k].id = -1;
    blocks_ready = true;
}

static log_block *block_find(int id)
{
    for (int k = 0; k < LOG_MAX_BLOCKS; k++)
        if (blocks[k].id == id)
            return &blocks[k];
    return NULL;
}

static int block_length(const log_block *b)
{
    int len = 0;
    for (int k = 0; k < b->n; k++)
        len += type_len[b->ops[k].fetch];
    return len;
}

/* log.c:425-470: ops (type, id16) triples appended to block `id`. */
static int block_append(int id, const uint8_t *ops, int n)
{
    log_block *b = block_find(id);
    if (b == NULL)
        return ENOENT;
    for (int k = 0; k < n; k++) {
        uint8_t fetch = ops[3 * k] & 0x0f;
        uint16_t var = (uint16_t)(ops[3 * k + 1] | ops[3 * k + 2] << 8);
        const char *group;
        if (fetch < 1 || fetch > 8)
            return EINVAL;
        if (block_length(b) + type_len[fetch] > LOG_MAX_LEN || b->n >= LOG_MAX_LEN)
            return E2BIG;
        const struct log_s *l = log_at(var, &group);
        if (l == NULL)
            return ENOENT; /* raw memory addresses (0xFFFF) are not served */
        b->ops[b->n].var = l;
        b->ops[b->n].fetch = fetch;
        b->n++;
    }
    return 0;
}

static int block_create(int id, const uint8_t *ops, int n)
{
    if (block_find(id) != NULL)
        return EEXIST;
    log_block *b = block_find(-1);
    if (b == NULL)
        return ENOMEM;
    memset(b, 0, sizeof *b);
    b->id = id;
    int r = block_append(id, ops, n);
    if (r != 0)
        b->id = -1;
    return r;
}

static int block_start(int id, uint32_t period_ms)
{
    log_block *b = block_find(id);
    if (b == NULL)
        return ENOENT;
    b->period_ms = period_ms < 10u ? 10u : period_ms;
    b->next_ms = serve_now_ms();
    b->started = true;
    return 0;
}

static void log_packet(const crtp_packet *in)
{
    const char *group;
    uint8_t d[CRTP_MAX_DATA];
    if (!blocks_ready)
        log_reset();
    if (in->size < 1)
        return;
    if (in->channel == 0) {
        if (in->data[0] == 3) {
            uint16_t count = 0;
            uint32_t crc = 2166136261u;
            for (const struct log_s *l = log_at(0, &group); l != NULL; l = log_at(++count, &group))
                crc = fnv(fnv(crc, group, 0), l->name, l->type);
            toc_info(in, count, crc, true);
        } else if (in->data[0] == 2 && in->size >= 3) {
            uint16_t id = (uint16_t)(in->data[1] | in->data[2] << 8);
            const struct log_s *l = log_at(id, &group);
            if (l == NULL) {
                d[0] = 2;
                reply(in, d, 1);
            } else {
                toc_item(in, id, (uint8_t)(l->type & 0x0f), group, l->name);
            }
        }
        return;
    }
    if (in->channel != 1)
        return;
    int ret = ENOEXEC;
    int id = in->size > 1 ? in->data[1] : 0;
    int nops = in->size > 2 ? (in->size - 2) / 3 : 0;
    switch (in->data[0]) {
    case 2: { /* delete */
        log_block *b = block_find(id);
        ret = b == NULL ? ENOENT : 0;
        if (b)
            b->id = -1;
        break;
    }
    case 3: /* start, period in 10 ms */
        ret = in->size > 2 ? block_start(id, in->data[2] * 10u) : EINVAL;
        break;
    case 4: { /* stop */
        log_block *b = block_find(id);
        ret = b == NULL ? ENOENT : 0;
        if (b)
            b->started = false;
        break;
    }
    case 5:
        log_reset();
        ret = 0;
        break;
    case 6:
        ret = block_create(id, in->data + 2, nops);
        break;
    case 7:
        ret = block_append(id, in->data + 2, nops);
        break;
    case 8: /* start v2, period in ms */
        ret = in->size > 3 ? block_start(id, (uint32_t)(in->data[2] | in->data[3] << 8)) : EINVAL;
        break;
    default:
        break;
    }
    d[0] = in->data[0];
    d[1] = (uint8_t)id;
    d[2] = (uint8_t)ret;
    reply(in, d, 3);
}

/* IEEE half precision (log.c's FP16) from a float, rounding toward zero. */
static uint16_t half(float f)
{
    uint32_t x;
    memcpy(&x, &f, 4);
    uint16_t sign = (uint16_t)((x >> 16) & 0x8000u);
    int e = (int)((x >> 23) & 0xff) - 127 + 15;
    if (e <= 0)
        return sign;
    if (e >= 31)
        return (uint16_t)(sign | 0x7c00u);
    return (uint16_t)(sign | (uint16_t)e << 10 | (uint16_t)((x >> 13) & 0x3ffu));
}

static double log_value(const struct log_s *l)
{
    switch (l->type & 0x0f) {
    case 1: return *(const uint8_t *)l->address;
    case 2: return *(const uint16_t *)l->address;
    case 3: return *(const uint32_t *)l->address;
    case 4: return *(const int8_t *)l->address;
    case 5: return *(const int16_t *)l->address;
    case 6: return *(const int32_t *)l->address;
    case 7: return *(const float *)l->address;
    default: return 0.0;
    }
}

static uint8_t put_value(uint8_t *d, uint8_t fetch, double v)
{
    switch (fetch) {
    case 1: d[0] = (uint8_t)(uint32_t)v; return 1;
    case 2: put16(d, (uint16_t)(uint32_t)v); return 2;
    case 3: put32(d, (uint32_t)v); return 4;
    case 4: d[0] = (uint8_t)(int8_t)v; return 1;
    case 5: put16(d, (uint16_t)(int16_t)v); return 2;
    case 6: put32(d, (uint32_t)(int32_t)v); return 4;
    case 7: {
        float f = (float)v;
        memcpy(d, &f, 4);
        return 4;
    }
    case 8: put16(d, half((float)v)); return 2;
    default: return 0;
    }
}

void crtp_tick(uint32_t now_ms)
{
    if (!blocks_ready)
        return;
    for (int k = 0; k < LOG_MAX_BLOCKS; k++) {
        log_block *b = &blocks[k];
        if (b->id < 0 || !b->started || (int32_t)(now_ms - b->next_ms) < 0)
            continue;
        b->next_ms += b->period_ms;
        crtp_packet p = {PORT_LOG, 2, 4, {0}};
        p.data[0] = (uint8_t)b->id;
        p.data[1] = (uint8_t)now_ms; /* log.c:568-575: ms, 24 bits */
        p.data[2] = (uint8_t)(now_ms >> 8);
        p.data[3] = (uint8_t)(now_ms >> 16);
        for (int j = 0; j < b->n; j++)
            p.size = (uint8_t)(p.size + put_value(p.data + p.size, b->ops[j].fetch,
                                                  log_value(b->ops[j].var)));
        crtp_send(&p);
    }
}

/* ---- setpoints ---- */

static float f32(const uint8_t *d)
{
    float f;
    memcpy(&f, d, 4);
    return f;
}

static void generic_setpoint(const crtp_packet *in)
{
    setpoint_t sp;
    memset(&sp, 0, sizeof sp);
    const uint8_t *d = in->data + 1;
    uint8_t type = in->data[0];
    if (type == 0) { /* stop: a null setpoint, motors off (crtp_commander_generic.c:86-91) */
        serve_client_setpoint(&sp);
        return;
    }
    if (in->size < 17)
        return;
    if (type == 7) { /* position x, y, z, yaw */
        sp.mode.x = sp.mode.y = sp.mode.z = modeAbs;
        sp.position.x = f32(d);
        sp.position.y = f32(d + 4);
        sp.position.z = f32(d + 8);
    } else if (type == 8) { /* velocity world vx, vy, vz, yawrate */
        sp.mode.x = sp.mode.y = sp.mode.z = modeVelocity;
        sp.velocity.x = f32(d);
        sp.velocity.y = f32(d + 4);
        sp.velocity.z = f32(d + 8);
    } else if (type == 10) { /* hover vx, vy, yawrate, z */
        sp.mode.x = sp.mode.y = modeVelocity;
        sp.mode.z = modeAbs;
        sp.velocity.x = f32(d);
        sp.velocity.y = f32(d + 4);
        sp.position.z = f32(d + 12);
    } else {
        return; /* other types are not served (docs/crazyflie.md) */
    }
    sp.mode.yaw = modeVelocity;
    serve_client_setpoint(&sp);
}

static void hl_packet(const crtp_packet *in)
{
    const uint8_t *d = in->data;
    switch (d[0]) {
    case 3: /* stop */
        serve_hl_stop();
        break;
    case 7: /* take-off 2: group, height, yaw, use current yaw, duration */
    case 8: /* land 2 */
        if (in->size >= 15) {
            if (d[0] == 7)
                serve_hl_takeoff(f32(d + 2), f32(d + 11));
            else
                serve_hl_land(f32(d + 2), f32(d + 11));
        }
        break;
    case 4: /* go to: group, relative, x, y, z, yaw, duration */
        if (in->size >= 23)
            serve_hl_go_to(f32(d + 3), f32(d + 7), f32(d + 11), f32(d + 19), d[2] != 0);
        break;
    case 12: /* go to 2: group, relative, linear, x, y, z, yaw, duration */
        if (in->size >= 24)
            serve_hl_go_to(f32(d + 4), f32(d + 8), f32(d + 12), f32(d + 20), d[2] != 0);
        break;
    default:
        break;
    }
}

void crtp_handle(const crtp_packet *in)
{
    uint8_t d[CRTP_MAX_DATA];
    switch (in->port) {
    case PORT_LINK:
        if (in->channel == 0) {
            reply(in, in->data, in->size); /* echo */
        } else if (in->channel == 1) {
            memset(d, 0, sizeof d);
            memcpy(d, "Bitcraze Crazyflie", 18);
            reply(in, d, CRTP_MAX_DATA);
        } else if (in->channel == 3) {
            reply(in, d, 0); /* null packet */
        }
        break;
    case PORT_PLATFORM:
        if (in->channel == 1 && in->size >= 1) {
            d[0] = in->data[0];
            if (in->data[0] == 0) {
                put32(d + 1, CRTP_PROTOCOL_VERSION);
                reply(in, d, 5);
            } else if (in->data[0] == 1 || in->data[0] == 2) {
                const char *s = in->data[0] == 1 ? "ph-formation serve" : "Simulated Crazyflie";
                size_t n = strlen(s);
                memcpy(d + 1, s, n);
                reply(in, d, (uint8_t)(1 + n));
            }
        }
        break;
    case PORT_MEM:
        if (in->channel == 0 && in->size >= 1 && in->data[0] == 1) {
            d[0] = 1;
            d[1] = 0; /* no memories */
            reply(in, d, 2);
        }
        break;
    case PORT_PARAM:
        param_packet(in);
        break;
    case PORT_LOG:
        log_packet(in);
        break;
    case PORT_RPYT:
        if (in->channel == 0 && in->size >= 14) {
            uint16_t thrust = (uint16_t)(in->data[12] | in->data[13] << 8);
            if (thrust == 0) { /* a zero setpoint: motors off */
                setpoint_t sp;
                memset(&sp, 0, sizeof sp);
                serve_client_setpoint(&sp);
            } /* attitude flight is not served */
        }
        break;
    case PORT_GENERIC:
        if (in->channel == 0 && in->size >= 1)
            generic_setpoint(in);
        else if (in->channel == 1 && in->size >= 1 && in->data[0] == 0)
            serve_client_notify_stop();
        break;
    case PORT_HL:
        if (in->size >= 1)
            hl_packet(in);
        break;
    case PORT_SUPERVISOR:  /* channel 1 commands: CMD_EMERGENCY_STOP 0x03 */
    case PORT_LOCALIZATION: /* channel 1 generic: EMERGENCY_STOP 3 (deprecated) */
        if (in->channel == 1 && in->size >= 1 && in->data[0] == 3)
            serve_emergency_stop();
        break;
    default:
        break;
    }
    (void)PORT_CONSOLE;
}
