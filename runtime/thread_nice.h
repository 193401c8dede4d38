#pragma once
// Background priority for stage threads whose work is off the latency path: a positive nice value
// for the calling thread only (Linux keeps nice per thread). Raising one's own nice value needs no
// privilege, so this does not fail in practice; the Status says why if it does.
#include "platform/status.h"

namespace plumb::runtime {

Status setCurrentThreadNice(int nice_value);

}  // namespace plumb::runtime
