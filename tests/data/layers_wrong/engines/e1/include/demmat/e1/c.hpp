#pragma once
// Wrong on purpose: an engine reaching into a variant.
#include "two.hpp"
