// "Did you mean ...?" for names the user typed: the valid name nearest to a misspelt one by
// edit distance (Levenshtein), for errors that name the closest valid name. Off the cyclic path.
#pragma once

#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace ecsim {

// Insertions, deletions and substitutions that turn `a` into `b`.
inline std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The name in `names` nearest to `name`, when it is near enough to be a likely misspelling (at
// most a third of the name's length, and at least one, edits away).
inline std::optional<std::string_view> closestName(std::string_view name,
                                                   const std::vector<std::string_view>& names) {
  std::optional<std::string_view> best;
  std::size_t bestDistance = std::max<std::size_t>(1, name.size() / 3) + 1;
  for (std::string_view candidate : names) {
    const std::size_t d = editDistance(name, candidate);
    if (d < bestDistance) {
      best = candidate;
      bestDistance = d;
    }
  }
  return best;
}

// The `count` names in `names` nearest to `name`, nearest first (in their given order among
// equally near ones), however far: for lists of candidates ("closest: Drive1.Statusword, ...").
inline std::vector<std::string_view> closestNames(std::string_view name,
                                                  const std::vector<std::string_view>& names,
                                                  std::size_t count) {
  std::vector<std::pair<std::size_t, std::size_t>> ranked;  // distance, index
  ranked.reserve(names.size());
  for (std::size_t i = 0; i < names.size(); ++i)
    ranked.emplace_back(editDistance(name, names[i]), i);
  std::stable_sort(ranked.begin(), ranked.end());
  std::vector<std::string_view> out;
  for (std::size_t i = 0; i < ranked.size() && i < count; ++i)
    out.push_back(names[ranked[i].second]);
  return out;
}

// "unknown argument 'durationMS'; did you mean 'durationMs'?" when one is close, else
// "unknown argument 'extra' (valid: cable, port, slave)".
inline std::string unknownNameText(std::string_view what, std::string_view name,
                                   const std::vector<std::string_view>& names) {
  std::string text = "unknown " + std::string(what) + " '" + std::string(name) + "'";
  if (auto best = closestName(name, names)) return text + "; did you mean '" + std::string(*best) + "'?";
  text += " (valid:";
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? " " : ", ") + std::string(names[i]);
  }
  return text + ")";
}

}  // namespace ecsim
