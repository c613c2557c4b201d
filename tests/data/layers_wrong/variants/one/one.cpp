// Wrong on purpose: a variant including another variant's folder (the first include is right).
#include "demmat/e1/a.hpp"
#include "two.hpp"
