#include "demmat/provenance.hpp"

#include <fstream>
#include <string>

#include <unistd.h>

namespace demmat {

// The model name, and what tells apart machines that a virtual machine names alike ("AMD EPYC"): the
// family and model numbers, and the widest x86 vector extension (fast's kernels take their width from it).
std::string cpu_model()
{
    std::ifstream in("/proc/cpuinfo");
    return cpu_model(in);
}

std::string cpu_model(std::istream& in)
{
    std::string line, name, family, model, vectors;
    auto value = [&line] {
        const auto colon = line.find(':');
        const auto start = colon == std::string::npos ? std::string::npos : line.find_first_not_of(' ', colon + 1);
        return start == std::string::npos ? std::string() : line.substr(start);
    };
    while (std::getline(in, line)) {
        if (line.rfind("model name", 0) == 0 && name.empty()) name = value();
        else if (line.rfind("cpu family", 0) == 0 && family.empty()) family = value();
        else if (line.rfind("model\t", 0) == 0 && model.empty()) model = value();
        else if (line.rfind("flags", 0) == 0 && vectors.empty()) {
            std::string flags = " ";
            flags += value();
            flags += ' ';
            vectors = flags.find(" avx512f ") != std::string::npos ? "AVX-512"
                      : flags.find(" avx2 ") != std::string::npos ? "AVX2"
                                                                   : "no AVX2";
        }
        if (!name.empty() && !family.empty() && !model.empty() && !vectors.empty()) break;
    }
    if (name.empty()) return "unknown";
    std::string detail;
    if (!family.empty()) {
        detail += "family ";
        detail += family;
        if (!model.empty()) {
            detail += " model ";
            detail += model;
        }
    }
    if (!vectors.empty()) {
        if (!detail.empty()) detail += ", ";
        detail += vectors;
    }
    if (detail.empty()) return name;
    name += " (";
    name += detail;
    name += ')';
    return name;
}

std::string host_name()
{
    char buf[256] = {};
    if (gethostname(buf, sizeof buf - 1) != 0) return "unknown";
    return buf;
}

} // namespace demmat
