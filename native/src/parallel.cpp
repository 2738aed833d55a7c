#include "topstoc/parallel.hpp"

#include <omp.h>

namespace topstoc {

void adapt_threads_to_load() { omp_set_dynamic(1); }

}  // namespace topstoc
