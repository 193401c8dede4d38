#pragma once
// The recording format's field packing lives in platform/ (the map file's codec in pipeline/ uses
// it too); this header keeps the drivers' include path.
#include "platform/byte_io.h"
