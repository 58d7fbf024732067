/* Stub of crazyflie-firmware src/modules/interface/stabilizer_types.h: the
 * setpoint type. Compile checks only. */
#pragma once

#include <stdbool.h>
#include <stdint.h>

typedef struct attitude_s {
    uint32_t timestamp;
    float roll;
    float pitch;
    float yaw;
} attitude_t;

struct vec3_s {
    uint32_t timestamp;
    float x;
    float y;
    float z;
};

typedef struct vec3_s point_t;
typedef struct vec3_s velocity_t;
typedef struct vec3_s acc_t;
typedef struct vec3_s jerk_t;

typedef struct quaternion_s {
    uint32_t timestamp;
    float x, y, z, w;
} quaternion_t;

typedef enum mode_e { modeDisable = 0, modeAbs, modeVelocity } stab_mode_t;

typedef struct {
    stab_mode_t x, y, z, roll, pitch, yaw, quat;
} setpoint_mode_t;

typedef struct setpoint_s {
    uint32_t timestamp;
    attitude_t attitude;     /* deg */
    attitude_t attitudeRate; /* deg/s */
    quaternion_t attitudeQuaternion;
    float thrust;
    point_t position;        /* m */
    velocity_t velocity;     /* m/s */
    acc_t acceleration;      /* m/s^2 */
    jerk_t jerk;             /* m/s^3 */
    bool velocity_body;      /* false: world frame */
    setpoint_mode_t mode;
} setpoint_t;
