// Part of the sc_fixed oracle suite: see quantise_oracle.inc.
#define TRM_ORACLE_PART_ARITHMETIC
#include "quantise_oracle.inc"
