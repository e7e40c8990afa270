#include "trm/cli.hpp"

int main(int argc, char** argv) { return trm::cli::run_main(argc, argv); }
