/* Stub of FreeRTOS task.h (the calls the app uses). Compile checks only. */
#pragma once

#include "FreeRTOS.h"

TickType_t xTaskGetTickCount(void);
void vTaskDelay(const TickType_t xTicksToDelay);
void vTaskDelayUntil(TickType_t *const pxPreviousWakeTime, const TickType_t xTimeIncrement);
