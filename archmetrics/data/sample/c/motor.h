#ifndef MOTOR_H
#define MOTOR_H

#include <stdint.h>

#define MOTOR_MAX_SPEED 1000

typedef enum { MOTOR_OK = 0, MOTOR_FAULT, MOTOR_STALLED } motor_status_t;

typedef struct {
    int16_t speed;
    int16_t target;
    motor_status_t status;
} motor_t;

void motor_init(motor_t *motor);
motor_status_t motor_step(motor_t *motor, int16_t current_ma);

#endif /* MOTOR_H */
