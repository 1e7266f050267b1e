// agnocast-cli: inspects the live agnocast system. Everything is in run_cli().
#include <iostream>

#include "cli.hpp"

int main(int argc, char** argv) {
  return agnocast::cli::run_cli(argc, argv, agnocast::cli::system_source(), std::cout, std::cerr);
}
