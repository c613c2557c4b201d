#pragma once
// Where a result came from: the commit, whether the tree was dirty, the compiler and its flags (fixed
// at build time), and the CPU it ran on (read at run time). Every result file carries these.
#include <istream>
#include <string>

namespace demmat {

struct Provenance {
    const char* commit;
    bool dirty;
    const char* compiler;
    const char* flags;
    const char* build_type;
};

const Provenance& build_provenance();
std::string cpu_model();   // from /proc/cpuinfo: the model name, family and model, widest vectors
std::string cpu_model(std::istream& cpuinfo);  // the same from a text in /proc/cpuinfo's format
std::string host_name();

} // namespace demmat
