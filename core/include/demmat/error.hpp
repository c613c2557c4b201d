#pragma once
#include <stdexcept>
#include <string>

namespace demmat {

// Every user-facing failure (bad input, capacity overflow, a run that blows up) is an Error whose
// message is one line that names the problem; the program prints it and exits non-zero.
class Error : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A run that became unstable: carries the step and particle so callers can report them.
class InstabilityError : public Error {
public:
    InstabilityError(const std::string& what, long long step, long long particle)
        : Error(what), step_(step), particle_(particle) {}
    long long step() const { return step_; }
    long long particle() const { return particle_; }

private:
    long long step_;
    long long particle_;
};

// A fixed capacity was exceeded: names the capacity and the value that would fit.
class CapacityError : public Error {
public:
    using Error::Error;
};

} // namespace demmat
