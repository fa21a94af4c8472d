#include "slavesim/foe/foe_files.hpp"

#include <algorithm>

namespace ecsim::slavesim::foe {

std::optional<std::string> softwareVersionIn(ConstBytes image) {
  const auto* begin = reinterpret_cast<const char*>(image.data());
  const std::string_view text(begin, image.size());
  const std::size_t at = text.rfind(kSoftwareVersionMarker);
  if (at == std::string_view::npos) return std::nullopt;
  std::string version;
  for (std::size_t i = at + kSoftwareVersionMarker.size();
       i < text.size() && version.size() < kMaxVersionLength; ++i) {
    const char c = text[i];
    if (c == '\0' || c == '\r' || c == '\n') break;
    version.push_back(c);
  }
  return version;
}

const std::vector<std::uint8_t>* FoeFiles::find(const std::string& name) const {
  auto it = files_.find(name);
  return it == files_.end() ? nullptr : &it->second;
}

void FoeFiles::store(const std::string& name, std::vector<std::uint8_t> data, bool writtenInBoot) {
  files_[name] = std::move(data);
  if (writtenInBoot) pending_ = name;
}

std::size_t FoeFiles::totalBytes() const {
  std::size_t n = 0;
  for (const auto& [name, data] : files_) n += data.size();
  return n;
}

void FoeFiles::installPending() {
  if (!pending_) return;
  if (const auto* image = find(*pending_); image != nullptr) {
    if (auto version = softwareVersionIn(*image)) installedVersion_ = std::move(version);
  }
  pending_.reset();
}

}  // namespace ecsim::slavesim::foe
