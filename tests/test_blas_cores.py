"""The OpenBLAS core types a test may force (tests.helpers.openblas_core_types):
only those whose instructions the processor has, read from /proc/cpuinfo's
flags, so that no test dies with SIGILL on a processor without them."""

from __future__ import annotations

import pytest

from tests.helpers import cpu_flags, openblas_core_types

AVX2 = {"sse", "sse2", "pni", "ssse3", "sse4_1", "sse4_2", "avx", "avx2", "fma"}
AVX512 = {"avx512f", "avx512bw", "avx512dq", "avx512vl", "avx512cd"}


@pytest.mark.parametrize("flags, expected", [
    (set(), ["Prescott"]),                                    # nothing known: SSE3 only
    ({"sse", "sse2", "pni", "avx"}, ["Prescott"]),            # AVX without AVX2
    (AVX2 - {"fma"}, ["Prescott"]),                           # AVX2 without FMA
    (AVX2, ["Prescott", "Haswell"]),                          # e.g. AMD EPYC before Zen 4
    (AVX2 | AVX512, ["Prescott", "Haswell", "SkylakeX"]),
    (AVX2 | AVX512 - {"avx512vl"}, ["Prescott", "Haswell"]),  # one AVX-512 subset missing
    (AVX2 | {"avx512f", "avx512cd", "avx512er", "avx512pf"},  # Xeon Phi: no BW, DQ, VL
     ["Prescott", "Haswell"]),
], ids=["none", "avx", "avx2-no-fma", "avx2", "avx512", "avx512-no-vl", "xeon-phi"])
def test_core_types_follow_the_cpuinfo_flags_on_x86_64(flags, expected):
    for machine in ("x86_64", "AMD64"):
        assert openblas_core_types(frozenset(flags), machine) == expected


@pytest.mark.parametrize("machine", ["aarch64", "arm64", "ppc64le", "s390x", "riscv64"])
def test_no_core_type_is_forced_off_x86_64(machine):
    assert openblas_core_types(frozenset(AVX2 | AVX512), machine) == []


def test_flags_are_read_from_the_first_flags_line(tmp_path):
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text("processor\t: 0\nvendor_id\t: AuthenticAMD\n"
                       "flags\t\t: fpu sse2 avx2 fma\nbugs\t\t: sysret_ss_attrs\n\n"
                       "processor\t: 1\nflags\t\t: fpu\n")
    assert cpu_flags(cpuinfo) == {"fpu", "sse2", "avx2", "fma"}
    assert openblas_core_types(cpu_flags(cpuinfo), "x86_64") == ["Prescott", "Haswell"]
    cpuinfo.write_text("processor\t: 0\nFeatures\t: fp asimd\n")    # an arm64 kernel's
    assert cpu_flags(cpuinfo) == frozenset()
    assert cpu_flags(tmp_path / "missing") == frozenset()
