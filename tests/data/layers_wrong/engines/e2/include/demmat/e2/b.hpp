#pragma once
// Wrong on purpose: an engine including another engine.
#include "demmat/e1/a.hpp"
