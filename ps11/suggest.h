// "Did you mean …?": the nearest known name to a word the user mistyped (instruction,
// command, option, keyword), by edit distance. Used by the assembler, the .ps11test parser
// and the command line, so every suggestion follows the same rule.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>

namespace ps11 {

// Optimal-string-alignment distance (insertions, deletions, substitutions and swaps of two
// neighbours each cost 1), ASCII case ignored. Returns limit + 1 as soon as the distance is
// known to exceed limit, so a huge word costs almost nothing.
size_t editDistance(std::string_view a, std::string_view b, size_t limit);

// The candidate nearest to word when it is close: distance at most 1 for words of up to 5
// characters, at most 2 from 6 on (a third of the length, so "dcl" or "foo" never turn into
// "mul" or "mov"); ties go to the earlier candidate. Empty when none is close or the word is
// one of the candidates.
std::string_view nearestName(std::string_view word, std::span<const std::string_view> candidates);
std::string_view nearestName(std::string_view word, std::initializer_list<std::string_view> candidates);

// "; did you mean 'mul'?" for the nearest candidate, or "" when nearestName finds none.
std::string didYouMean(std::string_view word, std::span<const std::string_view> candidates);
std::string didYouMean(std::string_view word, std::initializer_list<std::string_view> candidates);

}  // namespace ps11
