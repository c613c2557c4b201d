#pragma once
// Right: the harness includes the core.
#include "demmat/low.hpp"
#include <vector>
