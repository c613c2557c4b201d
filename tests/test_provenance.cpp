// The CPU a result names (provenance.hpp): a virtual machine's generic model name alone cannot tell two
// machines apart, so the name carries the family, the model and the widest vector extension.
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "demmat/provenance.hpp"

namespace {

std::string named(const std::string& cpuinfo)
{
    std::istringstream in(cpuinfo);
    return demmat::cpu_model(in);
}

TEST(Provenance, TheCpuNamesItsFamilyModelAndWidestVectors)
{
    // Two processors of one machine: the first's lines name it.
    const std::string zen3 = "processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 25\nmodel\t\t: 1\n"
                             "model name\t: AMD EPYC\nflags\t\t: fpu sse4_2 avx avx2 fma\n\n"
                             "processor\t: 1\ncpu family\t: 99\nmodel\t\t: 9\nmodel name\t: other\nflags\t\t: avx512f\n";
    EXPECT_EQ(named(zen3), "AMD EPYC (family 25 model 1, AVX2)");
    EXPECT_EQ(named("cpu family\t: 26\nmodel\t\t: 2\nmodel name\t: AMD EPYC\nflags\t\t: avx2 avx512f avx512vl\n"),
              "AMD EPYC (family 26 model 2, AVX-512)");
    // avx512f, not a flag that merely begins with it; no AVX2 said as such.
    EXPECT_EQ(named("model name\t: Old\nflags\t\t: sse2 avx512fx\n"), "Old (no AVX2)");
    // Without flags (another architecture's format): the name alone.
    EXPECT_EQ(named("model name\t: Some CPU\n"), "Some CPU");
    EXPECT_EQ(named("processor\t: 0\n"), "unknown");
}

} // namespace
