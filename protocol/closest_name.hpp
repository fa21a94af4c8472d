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

// Insertions, deletions, substitutions and swaps of two neighbouring letters that turn `a`
// into `b` (optimal string alignment distance), ignoring the case of ASCII letters: the slips
// of a typing hand ("durationMS", "Lnik", "drivse") are all one or no edit away.
inline std::size_t editDistance(std::string_view a, std::string_view b) {
  const auto same = [](char x, char y) {
    const auto lower = [](char c) {
      return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
    };
    return lower(x) == lower(y);
  };
  // Three rows of the (a.size()+1) x (b.size()+1) table: two back, one back, this one.
  std::vector<std::size_t> before(b.size() + 1), previous(b.size() + 1), row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    before.swap(previous);
    previous.swap(row);
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      row[j] = std::min(
          {previous[j] + 1, row[j - 1] + 1, previous[j - 1] + (same(a[i - 1], b[j - 1]) ? 0 : 1)});
      if (i > 1 && j > 1 && same(a[i - 1], b[j - 2]) && same(a[i - 2], b[j - 1])) {
        row[j] = std::min(row[j], before[j - 2] + 1);
      }
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

// "; did you mean 'Drive1'?" when a name in `names` is close to `name`, else "": for messages
// about names from a long list (slaves, cables) that is not worth listing.
inline std::string didYouMean(std::string_view name, const std::vector<std::string_view>& names) {
  if (auto best = closestName(name, names)) return "; did you mean '" + std::string(*best) + "'?";
  return {};
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
// "unknown argument 'extra' (valid: cable, port, slave)". `where` follows the name
// (" on <Scenario>"); `quote` surrounds the names: "'" for values, "<>" for elements.
inline std::string unknownNameText(std::string_view what, std::string_view name,
                                   const std::vector<std::string_view>& names,
                                   std::string_view where = {}, std::string_view quote = "''") {
  const std::string open(quote.substr(0, 1)), close(quote.substr(quote.size() - 1));
  const auto quoted = [&](std::string_view n) { return open + std::string(n) + close; };
  std::string text = "unknown " + std::string(what) + " " + quoted(name) + std::string(where);
  if (auto best = closestName(name, names)) return text + "; did you mean " + quoted(*best) + "?";
  if (names.empty()) return text + " (it takes none)";
  text += " (valid:";
  for (std::size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? " " : ", ") + (open == "'" ? std::string(names[i]) : quoted(names[i]));
  }
  return text + ")";
}

}  // namespace ecsim
