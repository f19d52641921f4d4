#pragma once
#include <ostream>

namespace ks {
/// Print the 21 rows of seed 000's Table 4 beside kinesweep's figures for the same parameters.
void print_table4(std::ostream& os);
}  // namespace ks
