/* Host side of port.h: no tick counter (the host run gives the reference
   trace, not the cost). */
#include "port.h"

void port_init(void) {}
uint32_t port_ticks(void) { return 0; }
uint32_t port_elapsed(uint32_t start, uint32_t stop) { return stop - start; }
uint32_t port_tick_hz(void) { return 0; }
uint32_t port_calibration_ticks(uint32_t iterations) {
  (void)iterations;
  return 0;
}
