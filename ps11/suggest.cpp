// Suggestions for mistyped names: a bounded edit distance and the rule for when a candidate
// is close enough to offer ("did you mean 'mul'?").
#include "ps11/suggest.h"

#include <algorithm>
#include <vector>

namespace ps11 {
namespace {

constexpr size_t kMaxSuggestDistance = 2;

char lowerAscii(char c) { return c >= 'A' && c <= 'Z' ? char(c - 'A' + 'a') : c; }

}  // namespace

size_t editDistance(std::string_view a, std::string_view b, size_t limit) {
    const size_t n = a.size(), m = b.size();
    if ((n > m ? n - m : m - n) > limit) return limit + 1;
    // Three rolling rows of the dynamic-programming table (two back for the swap).
    std::vector<size_t> prev2(m + 1), prev(m + 1), cur(m + 1);
    for (size_t j = 0; j <= m; ++j) prev[j] = j;
    for (size_t i = 1; i <= n; ++i) {
        cur[0] = i;
        size_t rowMin = cur[0];
        for (size_t j = 1; j <= m; ++j) {
            const bool same = lowerAscii(a[i - 1]) == lowerAscii(b[j - 1]);
            size_t d = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (same ? 0 : 1)});
            if (i > 1 && j > 1 && lowerAscii(a[i - 1]) == lowerAscii(b[j - 2]) &&
                lowerAscii(a[i - 2]) == lowerAscii(b[j - 1]))
                d = std::min(d, prev2[j - 2] + 1);
            cur[j] = d;
            rowMin = std::min(rowMin, d);
        }
        if (rowMin > limit) return limit + 1;
        std::swap(prev2, prev);
        std::swap(prev, cur);
    }
    return std::min(prev[m], limit + 1);
}

std::string_view nearestName(std::string_view word, std::span<const std::string_view> candidates) {
    // A third of the word's length, at least 1 and at most kMaxSuggestDistance.
    const size_t limit = std::clamp<size_t>(word.size() / 3, 1, kMaxSuggestDistance);
    std::string_view best;
    size_t bestDistance = limit + 1;
    for (std::string_view c : candidates) {
        const size_t d = editDistance(word, c, limit);
        if (d == 0) return {};
        if (d < bestDistance) {
            best = c;
            bestDistance = d;
        }
    }
    return best;
}

std::string_view nearestName(std::string_view word, std::initializer_list<std::string_view> candidates) {
    return nearestName(word, std::span<const std::string_view>(candidates.begin(), candidates.size()));
}

std::string didYouMean(std::string_view word, std::span<const std::string_view> candidates) {
    std::string_view best = nearestName(word, candidates);
    return best.empty() ? std::string() : "; did you mean '" + std::string(best) + "'?";
}

std::string didYouMean(std::string_view word, std::initializer_list<std::string_view> candidates) {
    return didYouMean(word, std::span<const std::string_view>(candidates.begin(), candidates.size()));
}

}  // namespace ps11
