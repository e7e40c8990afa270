// The simulation loop of trm_golden_tb. Verilator's own (--main) aborts the process on $fatal, a SIGABRT that ctest
// reads as a crash; this one lets $fatal end the simulation and returns 1, so a refused configuration or a failed
// check is an ordinary failing exit with its message.
// Verilator's runtime headers do not build under -Wextra -Werror (an unused parameter in verilated_types.h).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include "Vtrm_golden_tb.h"
#include "verilated.h"
#pragma GCC diagnostic pop

#include <memory>

int main(int argc, char** argv) {
  const auto context = std::make_unique<VerilatedContext>();
  context->commandArgs(argc, argv);
  context->fatalOnError(false);
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
