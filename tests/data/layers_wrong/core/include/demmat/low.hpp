#pragma once
// Wrong on purpose: the core reaching up into the harness.
#include "demmat/high.hpp"
