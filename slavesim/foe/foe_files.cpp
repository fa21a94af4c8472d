#include "slavesim/foe/foe_files.hpp"

#include <algorithm>
#include <array>

#include "slavesim/foe/foe_folder.hpp"

namespace ecsim::slavesim::foe {

namespace {

std::string_view asText(ConstBytes bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

// The version text at the start of `after` (the bytes following the marker).
std::string versionText(std::string_view after) {
  std::string version;
  for (std::size_t i = 0; i < after.size() && version.size() < kMaxVersionLength; ++i) {
    const char c = after[i];
    if (c == '\0' || c == '\r' || c == '\n') break;
    version.push_back(c);
  }
  return version;
}

}  // namespace

std::optional<std::string> softwareVersionIn(ConstBytes image) {
  const std::string_view text = asText(image);
  const std::size_t at = text.rfind(kSoftwareVersionMarker);
  if (at == std::string_view::npos) return std::nullopt;
  return versionText(text.substr(at + kSoftwareVersionMarker.size()));
}

std::optional<std::string> softwareVersionIn(const FoeFile& image) {
  const std::optional<std::size_t> at = image.rfind(kSoftwareVersionMarker);
  if (!at) return std::nullopt;
  std::array<std::uint8_t, kMaxVersionLength> after{};
  const std::size_t n = image.copyOut(*at + kSoftwareVersionMarker.size(), after);
  return versionText(asText(ConstBytes(after).first(n)));
}

void FoeFile::append(ConstBytes bytes) {
  while (!bytes.empty()) {
    if (chunks_.empty() || chunks_.back().size() == kChunkBytes) {
      chunks_.emplace_back().reserve(kChunkBytes);
    }
    std::vector<std::uint8_t>& last = chunks_.back();
    const std::size_t n = std::min(bytes.size(), kChunkBytes - last.size());
    last.insert(last.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
    bytes = bytes.subspan(n);
    size_ += n;
  }
}

std::size_t FoeFile::copyOut(std::size_t offset, Bytes out) const {
  std::size_t copied = 0;
  while (copied < out.size() && offset < size_) {
    const std::vector<std::uint8_t>& chunk = chunks_[offset / kChunkBytes];
    const std::size_t at = offset % kChunkBytes;
    const std::size_t n = std::min(out.size() - copied, chunk.size() - at);
    std::copy_n(chunk.begin() + static_cast<std::ptrdiff_t>(at), n,
                out.begin() + static_cast<std::ptrdiff_t>(copied));
    copied += n;
    offset += n;
  }
  return copied;
}

std::optional<std::size_t> FoeFile::rfind(std::string_view text) const {
  if (text.empty() || text.size() > kChunkBytes) return std::nullopt;
  // From the last chunk back: an occurrence inside chunk i starts before any that straddles
  // chunks i and i+1 (every chunk but the last is full).
  std::vector<std::uint8_t> seam;
  for (std::size_t i = chunks_.size(); i-- > 0;) {
    if (i + 1 < chunks_.size()) {
      const std::size_t start = (i + 1) * kChunkBytes - (text.size() - 1);
      seam.resize(2 * (text.size() - 1));
      const std::size_t n = copyOut(start, seam);
      const std::size_t at = asText(ConstBytes(seam).first(n)).rfind(text);
      if (at != std::string_view::npos) return start + at;
    }
    const std::size_t at = asText(chunks_[i]).rfind(text);
    if (at != std::string_view::npos) return i * kChunkBytes + at;
  }
  return std::nullopt;
}

std::vector<std::uint8_t> FoeFile::bytes() const {
  std::vector<std::uint8_t> all;
  all.reserve(size_);
  for (const auto& chunk : chunks_) all.insert(all.end(), chunk.begin(), chunk.end());
  return all;
}

const FoeFile* FoeFiles::find(const std::string& name) const {
  auto it = files_.find(name);
  return it == files_.end() ? nullptr : it->second.get();
}

std::shared_ptr<const FoeFile> FoeFiles::share(const std::string& name) const {
  auto it = files_.find(name);
  return it == files_.end() ? nullptr : it->second;
}

FoeFiles::FoeFiles() = default;
FoeFiles::~FoeFiles() = default;

Result<std::shared_ptr<FoeFiles>> FoeFiles::keptIn(const std::filesystem::path& folder) {
  FoeFolderContent content;
  ECSIM_ASSIGN_OR_RETURN(auto opened, FoeFolder::open(folder, content, kMaxFoeFileBytes));
  auto files = std::make_shared<FoeFiles>();
  for (auto& [name, file] : content.files) {
    files->files_[name] = std::make_shared<const FoeFile>(std::move(file));
  }
  files->pending_ = std::move(content.pending);
  files->installedVersion_ = std::move(content.installedVersion);
  files->folder_ = std::make_unique<FoeFolder>(std::move(opened));
  if (files->pending_ && files->find(*files->pending_) == nullptr) {
    return makeError(ErrorCode::kInvalidArgument, (folder / "firmware").string() +
                                                      ": the pending image '" + *files->pending_ +
                                                      "' is not in the folder");
  }
  ECSIM_TRY(files->installPending());
  return files;
}

Status FoeFiles::beginWrite(const std::string& name) {
  return folder_ ? folder_->begin(name) : okStatus();
}

Status FoeFiles::appendWrite(ConstBytes bytes) {
  return folder_ ? folder_->append(bytes) : okStatus();
}

void FoeFiles::abandonWrite() {
  if (folder_) folder_->abandon();
}

Status FoeFiles::store(const std::string& name, FoeFile data, bool writtenInBoot) {
  if (folder_) {
    ECSIM_TRY(folder_->finish());
    if (writtenInBoot) ECSIM_TRY(folder_->saveFirmwareRecord(name, installedVersion_));
  }
  files_[name] = std::make_shared<const FoeFile>(std::move(data));
  if (writtenInBoot) pending_ = name;
  return okStatus();
}

std::size_t FoeFiles::totalBytes() const {
  std::size_t n = 0;
  for (const auto& [name, data] : files_) n += data->size();
  return n;
}

Status FoeFiles::installPending() {
  if (!pending_) return okStatus();
  if (const auto* image = find(*pending_); image != nullptr) {
    if (auto version = softwareVersionIn(*image)) installedVersion_ = std::move(version);
  }
  pending_.reset();
  return folder_ ? folder_->saveFirmwareRecord(pending_, installedVersion_) : okStatus();
}

}  // namespace ecsim::slavesim::foe
