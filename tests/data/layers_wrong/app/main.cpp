// Right: the front end includes any layer below it.
#include "demmat/high.hpp"
#include "two.hpp"
int main() { return 0; }
