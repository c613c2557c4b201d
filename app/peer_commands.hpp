#pragma once
// The `demmat` subcommands that exchange particles with LAMMPS and LIGGGHTS (docs/peers.md):
// export-lammps, import-lammps, and dump (a run that writes LAMMPS-style dump frames).
#include <memory>

#include <CLI/CLI.hpp>

namespace demmat {

class PeerCommands {
public:
    explicit PeerCommands(CLI::App& app);
    ~PeerCommands();
    // The exit status of the subcommand given, or -1 when none of these was given. Throws Error.
    int dispatch();

private:
    struct Args;
    std::unique_ptr<Args> a_;
};

} // namespace demmat
