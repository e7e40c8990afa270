// The simulation loop of trm_golden_tb, and what $fatal does. Verilator's own (--main, vl_stop) aborts the process on
// $fatal, a SIGABRT that ctest reads as a crash; and with Verilator's non-fatal mode the process would run on past
// the $fatal (to a later $finish and exit status 0). Here $fatal, $stop and $error end the simulation at once with
// exit status 1, as an HDL simulator's batch run does.
// Verilator's runtime headers do not build under -Wextra -Werror (an unused parameter in verilated_types.h).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include "Vtrm_golden_tb.h"
#include "verilated.h"
#pragma GCC diagnostic pop

#include <cstdlib>
#include <memory>

// Replaces Verilator's (VL_USER_STOP is defined for this target).
void vl_stop(const char* filename, int linenum, const char* hier) {
  VL_PRINTF("%%Error: %s:%d: simulation stopped%s%s\n", filename ? filename : "?", linenum,
            hier && *hier ? " in " : "", hier && *hier ? hier : "");
  Verilated::runFlushCallbacks();
  std::exit(1);
}

int main(int argc, char** argv) {
  const auto context = std::make_unique<VerilatedContext>();
  context->commandArgs(argc, argv);
  const auto top = std::make_unique<Vtrm_golden_tb>(context.get());
  while (!context->gotFinish()) {
    top->eval();
    if (!top->eventsPending()) break;
    context->time(top->nextTimeSlot());
  }
  if (!context->gotFinish()) VL_PRINTF("%%Error: trm_golden_tb: the simulation ran out of events before $finish\n");
  top->final();
  return context->gotError() || !context->gotFinish() ? 1 : 0;
}
