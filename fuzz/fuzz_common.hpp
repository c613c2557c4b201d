#pragma once
// What every fuzz target checks besides the sanitizers: a reader rejects bad input only by throwing
// demmat::Error (which demmat prints as its one-line error) and its message is one line. Anything else
// (another exception, a multi-line message) aborts, which libFuzzer reports as a crash.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "demmat/error.hpp"

namespace demmat::fuzz {

[[noreturn]] inline void defect(const std::string& what)
{
    std::fprintf(stderr, "fuzz defect: %s\n", what.c_str());
    std::abort();
}

template <class F>
void expect_clean(F&& f)
{
    try {
        f();
    } catch (const Error& e) {
        const std::string m = e.what();
        if (m.find('\n') != std::string::npos || m.find('\r') != std::string::npos)
            defect("an error message spans several lines: " + m);
    } catch (const std::exception& e) {
        defect(std::string("an exception other than demmat::Error escaped: ") + e.what());
    }
}

} // namespace demmat::fuzz
