/* Host program of examples/cli/codegen.sh: runs the controller module that
 * `pneumid codegen` wrote (tanks_mpc.h/.c) in closed loop with the plant
 * module it wrote next to it (--with-plant tanks_plant), on the set-point and
 * load of a trace of `pneumid control -o` read from stdin (columns
 * t,r,y,y_meas,u,d), and prints t,r,y,u for every sample, so that the script
 * can compare the module's loop with the library's.
 *
 * On the real process the loop body is the same with the measured level in
 * place of the plant module; the module works in the model's deviation
 * variables, so with the operating point (U0, Y0) of the model file:
 *
 *   u_pump = U0 + tanks_mpc_step(&ctrl, level_setpoint - Y0, level - Y0);
 */
#include <stdio.h>

#include "tanks_mpc.h"
#include "tanks_plant.h"

int main(void) {
  static tanks_mpc_state ctrl; /* all controller state, owned by the caller */
  static tanks_plant_state plant;
  char line[512];
  double t, r, y_lib, y_meas_lib, u_lib, d;
  tanks_mpc_init(&ctrl);       /* at rest: u = 0, y = 0 */
  tanks_plant_reset(&plant, 0.0);
  printf("t,r,y,u\n");
  while (fgets(line, sizeof line, stdin)) {
    if (sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf", &t, &r, &y_lib, &y_meas_lib, &u_lib, &d) != 6) {
      continue; /* the header */
    }
    {
      /* every TANKS_MPC_TS seconds: measure, compute, apply */
      const double y = tanks_plant_output(&plant, 0.0) + d;
      const double u = tanks_mpc_step(&ctrl, r, y);
      tanks_plant_advance(&plant, u);
      printf("%.17g,%.17g,%.17g,%.17g\n", t, r, y, u);
    }
  }
  return ctrl.qp_failures == 0 ? 0 : 1;
}
