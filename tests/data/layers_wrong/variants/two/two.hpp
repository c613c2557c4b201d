#pragma once
// Right: a variant includes an engine.
#include "demmat/e1/a.hpp"
