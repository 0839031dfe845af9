/* Closed loop of a generated controller (ctrl.h, `pneumid codegen --prefix
   ctrl`) against a generated linear plant (plant.h, `--with-plant plant`):
   a set-point staircase and a load step on the output, the input clipped to
   the actuator range [U_MIN, U_MAX] with ctrl_applied() when clipped.
   Prints one line per step, "k y u" with y and u as the bit patterns of their
   IEEE values (exact, whatever printf supports), then the cost of the
   controller steps in ticks of port.h. Runs the same on the host and on the
   target, whose traces are compared (run_test.sh). */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "ctrl.h"
#include "plant.h"
#include "port.h"

#ifndef STEPS
#define STEPS 2000
#endif
#define U_MIN 0.0
#define U_MAX 100.0

static ctrl_state controller;
static plant_state plant;

static double setpoint(int k) {
  static const double levels[] = {10.0, 40.0, 80.0, 30.0, 60.0};
  return levels[(k / 400) % 5];
}

static double load(int k) { return k >= 1300 ? -10.0 : 0.0; }

static void print_bits(double v, int single) {
  if (single) {
    float f = (float)v;
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    printf(" %08lx", (unsigned long)b);
  } else {
    uint64_t b;
    memcpy(&b, &v, sizeof b);
    printf(" %08lx%08lx", (unsigned long)(b >> 32), (unsigned long)(b & 0xFFFFFFFFu));
  }
}

int main(void) {
  const int single = sizeof(ctrl_real) == 4;
  uint64_t total = 0;
  uint32_t worst = 0;
  int k;
  port_init();
  plant_reset(&plant, (plant_real)0);
  ctrl_init(&controller);
  for (k = 0; k < STEPS; ++k) {
    const double y = (double)plant_output(&plant, (plant_real)0) + load(k);
    uint32_t start, elapsed;
    ctrl_real u;
    double ua;
    start = port_ticks();
    u = ctrl_step(&controller, (ctrl_real)setpoint(k), (ctrl_real)y);
    elapsed = port_elapsed(start, port_ticks());
    total += elapsed;
    if (elapsed > worst) worst = elapsed;
    ua = (double)u < U_MIN ? U_MIN : ((double)u > U_MAX ? U_MAX : (double)u);
    if (ua != (double)u) ctrl_applied(&controller, (ctrl_real)ua);
    plant_advance(&plant, (plant_real)ua);
    printf("%d", k);
    print_bits(y, single);
    print_bits((double)u, single);
    printf("\n");
  }
  {
    const uint32_t start = port_ticks();
    const uint32_t empty = port_elapsed(start, port_ticks());
    printf("calibration loop_instructions=%lu loop_ticks=%lu empty_ticks=%lu\n",
           (unsigned long)(2u * 200000u), (unsigned long)port_calibration_ticks(200000u),
           (unsigned long)empty);
  }
  printf("cost steps=%d ticks_total=%lu ticks_max=%lu tick_hz=%lu state_bytes=%lu\n", STEPS,
         (unsigned long)total, (unsigned long)worst, (unsigned long)port_tick_hz(),
         (unsigned long)sizeof(ctrl_state));
  return 0;
}
