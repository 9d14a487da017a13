// Levenshtein distance, for "did you mean ...?" suggestions (scene commands,
// subcommands, options).
#pragma once

#include <algorithm>
#include <string_view>
#include <vector>

namespace snell {

inline int editDistance(std::string_view a, std::string_view b) {
    std::vector<int> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
    for (std::size_t i = 1; i <= a.size(); ++i) {
        int diagonal = row[0];
        row[0] = static_cast<int>(i);
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const int above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
            diagonal = above;
        }
    }
    return row[b.size()];
}

// The candidate nearest to `word` within `maxDistance` edits, or empty.
template <class Names>
std::string_view nearestName(std::string_view word, const Names& candidates, int maxDistance) {
    std::string_view best;
    int bestDistance = maxDistance + 1;
    for (std::string_view c : candidates) {
        const int d = editDistance(word, c);
        if (d < bestDistance) {
            bestDistance = d;
            best = c;
        }
    }
    return best;
}

}  // namespace snell
