// Internal to the random-case generator (runner/random_program.h): the dice both halves draw
// from, and the test file around a program (runner/random_environment.cpp), which the program
// generator and shrinker (runner/random_program.cpp) call.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "ps11/ir.h"

namespace ps11test {

// Uniform draws from the engine's raw output rather than std::uniform_*_distribution, whose
// algorithms differ between standard libraries: a seed gives the same case everywhere.
class Dice {
public:
    explicit Dice(std::mt19937_64& rng) : m_rng(rng) {}
    int below(size_t n) { return int(m_rng() % n); }
    int range(int lo, int hi) { return lo + below(size_t(hi - lo + 1)); }
    bool chance(int percent) { return below(100) < percent; }
    uint32_t word() { return uint32_t(m_rng() >> 32); }
    // A multiple of 1/1000 in [lo, hi].
    double thousandths(double lo, double hi) { return range(int(lo * 1000), int(hi * 1000)) / 1000.0; }
    template <class T>
    const T& pick(const std::vector<T>& v) {
        return v[size_t(below(v.size()))];
    }

private:
    std::mt19937_64& m_rng;
};

// The file around `shader`: randomCase's whole environment (`full`) or caseForProgram's plain one.
std::string testTextOf(Dice& dice, const ps11::Program& program, const std::string& shader, int width, int height,
                       bool full);

// Whether `text` parses as a .ps11test file.
bool parsesAsTestFile(const std::string& text);

// Simpler versions of a case file's environment, the boldest first (the shrinker's).
std::vector<std::string> simplerEnvironments(const std::string& text);

}  // namespace ps11test
