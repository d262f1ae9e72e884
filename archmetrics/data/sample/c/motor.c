#include <stdlib.h>
#include "motor.h"

#define STALL_CURRENT_MA 2500
#define RAMP 50

void motor_init(motor_t *motor)
{
    motor->speed = 0;
    motor->target = 0;
    motor->status = MOTOR_OK;
}

static int16_t clamp(int16_t value)
{
    if (value > MOTOR_MAX_SPEED)
        return MOTOR_MAX_SPEED;
    if (value < -MOTOR_MAX_SPEED)
        return -MOTOR_MAX_SPEED;
    return value;
}

motor_status_t motor_step(motor_t *motor, int16_t current_ma)
{
    int16_t error = motor->target - motor->speed;

    if (current_ma > STALL_CURRENT_MA && abs(motor->speed) < RAMP) {
        motor->status = MOTOR_STALLED;
        motor->speed = 0;
        return motor->status;
    }
    switch (motor->status) {
    case MOTOR_FAULT:
        motor->speed = 0;
        break;
    case MOTOR_STALLED:
    case MOTOR_OK:
        motor->speed = clamp(motor->speed + (error > RAMP ? RAMP : (error < -RAMP ? -RAMP : error)));
        motor->status = MOTOR_OK;
        break;
    }
    return motor->status;
}
