#pragma once
// Shared helpers for the tests: scenes in memory, runs of a variant, and the list of variants.
#include <memory>
#include <string>
#include <vector>

#include "demmat/checker.hpp"
#include "demmat/driver.hpp"
#include "demmat/registry.hpp"
#include "demmat/scenes.hpp"

namespace demmat::test {

// A scene with its initial state and setup, kept together (Setup points into the other two).
struct Case {
    Scene scene;
    State state;
    Setup setup;
    explicit Case(Scene s) : scene(std::move(s)), state(initial_state(scene)), setup(Setup::make(scene, state)) {}
    Case(Scene s, State st) : scene(std::move(s)), state(std::move(st)), setup(Setup::make(scene, state)) {}
};

inline std::vector<std::string> variant_names() { return registry().names(); }

// Runs `steps` steps of a variant and returns it with its driver.
struct VariantRun {
    std::unique_ptr<Variant> variant;
    std::unique_ptr<Driver> driver;
    VariantRun(const std::string& name, const Setup& setup)
        : variant(registry().find(name).create()), driver(std::make_unique<Driver>(*variant, setup)) {}
    Snapshot snapshot() const
    {
        Snapshot s;
        variant->snapshot(s);
        return s;
    }
};

// Turns a variant name into a valid test-name suffix.
inline std::string param_name(const std::string& s)
{
    std::string out;
    for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    return out;
}

} // namespace demmat::test
