#pragma once
// Right: an engine includes the core and the harness.
#include "demmat/low.hpp"
#include "demmat/high.hpp"
