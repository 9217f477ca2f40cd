/* C API calls made from C, where an enum parameter takes any int value (as from a C caller
 * or ctypes); the C++ harnesses cannot form such values without undefined behaviour. */
#include "hairis/hairis.h"

hairis_sampler *hairis_fuzz_sampler_create(int strategy, const hairis_fiber *fiber,
                                           const hairis_tables *tables, float multiple_weight,
                                           int n_h);

hairis_sampler *hairis_fuzz_sampler_create(int strategy, const hairis_fiber *fiber,
                                           const hairis_tables *tables, float multiple_weight,
                                           int n_h) {
    return hairis_sampler_create((hairis_strategy)strategy, fiber, tables, multiple_weight, n_h);
}
