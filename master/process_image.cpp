#include "master/process_image.hpp"

#include <algorithm>

#include "protocol/coe.hpp"

namespace ecsim::master {
namespace {

constexpr std::size_t kFrameDatagramCapacity =
    kMaxFrameSize - kEthernetHeaderSize - kEtherCatHeaderSize;

struct Area {
  std::uint32_t start;  // process image offset
  std::uint32_t end;
};

bool overlaps(std::uint32_t aStart, std::uint32_t aEnd, std::uint32_t bStart, std::uint32_t bEnd) {
  return aStart < bEnd && bStart < aEnd;
}

Status layoutSlave(const SlaveInfo& slave, const SlaveProcessData& data, SlaveLayout& out) {
  out.position = slave.position;
  out.station = slave.station;
  out.fmmuCount = slave.fmmuCount;
  const auto& siiSms = slave.siiContents.syncManagers;
  for (const auto& assignment : data.sms) {
    if (assignment.sm >= siiSms.size()) {
      return makeError(ErrorCode::kInvalidArgument,
                       slave.label() + ": process data for SM" + std::to_string(assignment.sm) +
                           ", which its SII SM category does not have");
    }
    const SiiSyncManager& sii = siiSms[assignment.sm];
    const std::uint32_t bits = assignment.bitLength();
    const std::uint32_t bytes = (bits + 7) / 8;
    if (bytes > 0xFFFF) {
      return makeError(ErrorCode::kTooLarge, slave.label() + ": SM" +
                                                 std::to_string(assignment.sm) + " would hold " +
                                                 std::to_string(bytes) + " bytes");
    }
    SmLayout sm;
    sm.sm = assignment.sm;
    sm.outputs = assignment.outputs;
    sm.setting = syncManagerChannel(sii.startAddress, static_cast<std::uint16_t>(bytes), sii.control,
                                    bytes > 0);
    sm.bitLength = bits;
    sm.pdos = assignment.pdos;
    out.sms.push_back(std::move(sm));
  }
  return okStatus();
}

}  // namespace

Result<ProcessImageLayout> planProcessImage(const std::vector<SlaveInfo>& slaves,
                                            const std::vector<SlaveProcessData>& processData,
                                            const LayoutOptions& options) {
  if (slaves.size() != processData.size()) {
    return makeError(ErrorCode::kInvalidArgument,
                     "process data for " + std::to_string(processData.size()) +
                         " slaves, bus has " + std::to_string(slaves.size()));
  }
  if (options.maxDatagramData == 0 || options.maxDatagramData > Transport::kMaxDatagramData) {
    return makeError(ErrorCode::kInvalidArgument, "datagram size limit out of range");
  }
  ProcessImageLayout layout;
  layout.logicalBase = options.logicalBase;
  for (std::size_t i = 0; i < slaves.size(); ++i) {
    SlaveLayout sl;
    ECSIM_TRY(layoutSlave(slaves[i], processData[i], sl));
    layout.slaves.push_back(std::move(sl));
  }
  // Outputs of every slave, then inputs of every slave.
  std::uint32_t offset = 0;
  for (bool outputs : {true, false}) {
    for (auto& sl : layout.slaves) {
      (outputs ? sl.outputOffset : sl.inputOffset) = offset;
      for (auto& sm : sl.sms) {
        if (sm.outputs != outputs || sm.setting.length == 0) continue;
        sm.logicalStart = layout.logicalBase + offset;
        offset += sm.setting.length;
        (outputs ? sl.outputBytes : sl.inputBytes) += sm.setting.length;
      }
    }
    if (outputs) layout.outputBytes = offset;
  }
  layout.inputBytes = offset - layout.outputBytes;
  for (auto& sl : layout.slaves) {
    sl.fmmus = fmmusOf(sl);
    if (sl.fmmus.size() > sl.fmmuCount) {
      return makeError(ErrorCode::kUnsupported,
                       slaves[sl.position].label() + ": needs " + std::to_string(sl.fmmus.size()) +
                           " FMMUs, its ESC has " + std::to_string(sl.fmmuCount));
    }
  }
  // Datagrams over the image, split at area boundaries where possible.
  std::vector<Area> areas;
  for (bool outputs : {true, false}) {
    for (const auto& sl : layout.slaves) {
      const std::uint32_t start = outputs ? sl.outputOffset : sl.inputOffset;
      const std::uint32_t bytes = outputs ? sl.outputBytes : sl.inputBytes;
      if (bytes > 0) areas.push_back({start, start + bytes});
    }
  }
  const auto maxData = static_cast<std::uint32_t>(options.maxDatagramData);
  std::vector<Area> ranges;
  if (!areas.empty()) {
    Area current{areas.front().start, areas.front().start};
    for (const Area& area : areas) {
      if (area.end - current.start <= maxData) {
        current.end = area.end;
        continue;
      }
      if (current.end > current.start) ranges.push_back(current);
      current = {area.start, area.start};
      while (area.end - current.start > maxData) {
        ranges.push_back({current.start, current.start + maxData});
        current.start += maxData;
      }
      current.end = area.end;
    }
    if (current.end > current.start) ranges.push_back(current);
  }
  std::size_t frame = 0;
  std::size_t frameUsed = 0;
  for (const Area& range : ranges) {
    LogicalDatagram d;
    d.logicalStart = layout.logicalBase + range.start;
    d.length = static_cast<std::uint16_t>(range.end - range.start);
    for (const auto& sl : layout.slaves) {
      const bool out = sl.outputBytes > 0 && overlaps(range.start, range.end, sl.outputOffset,
                                                      sl.outputOffset + sl.outputBytes);
      const bool in = sl.inputBytes > 0 && overlaps(range.start, range.end, sl.inputOffset,
                                                    sl.inputOffset + sl.inputBytes);
      if (!out && !in) continue;
      const auto add = static_cast<std::uint16_t>((out ? 2 : 0) + (in ? 1 : 0));
      d.expectedWkc = static_cast<std::uint16_t>(d.expectedWkc + add);
      d.slaves.push_back(sl.position);
      d.contributions.push_back(add);
    }
    const std::size_t wire = kDatagramOverhead + d.length;
    if (frameUsed + wire > kFrameDatagramCapacity) {
      ++frame;
      frameUsed = 0;
    }
    frameUsed += wire;
    d.frame = frame;
    layout.datagrams.push_back(std::move(d));
  }
  layout.frameCount = layout.datagrams.empty() ? 0 : frame + 1;
  return layout;
}

std::vector<FmmuBlock> fmmusOf(const SlaveLayout& slave) {
  std::vector<FmmuBlock> fmmus;
  for (bool outputs : {true, false}) {
    for (const auto& sm : slave.sms) {
      if (sm.outputs != outputs || sm.setting.length == 0) continue;
      FmmuBlock f;
      f.logicalStart = sm.logicalStart;
      f.length = sm.setting.length;
      f.physicalStart = sm.setting.start;
      f.write = outputs;
      f.read = !outputs;
      f.enable = true;
      fmmus.push_back(f);
    }
  }
  return fmmus;
}

void addProcessDataSetup(DatagramBatch& batch, const ProcessImageLayout& layout) {
  for (const auto& sl : layout.slaves) {
    for (const auto& sm : sl.sms) {
      batch.add().fpwr(sl.station, reg::smChannel(sm.sm), sm.setting.bytes());
    }
    const std::size_t channels = std::max<std::size_t>(sl.fmmuCount, sl.fmmus.size());
    if (channels == 0) continue;
    std::vector<std::uint8_t> fmmus(channels * reg::kFmmuSize, 0);
    for (std::size_t n = 0; n < sl.fmmus.size(); ++n) {
      sl.fmmus[n].emit(Bytes(fmmus).subspan(n * reg::kFmmuSize));
    }
    batch.add().fpwr(sl.station, reg::fmmuChannel(0), fmmus);
  }
}

std::vector<ProcessVariable> processVariables(const ProcessImageLayout& layout) {
  std::vector<ProcessVariable> out;
  for (const auto& sl : layout.slaves) {
    for (const auto& sm : sl.sms) {
      if (sm.setting.length == 0) continue;
      std::uint32_t bit = (sm.logicalStart - layout.logicalBase) * 8;
      for (const auto& pdo : sm.pdos) {
        for (const auto& e : pdo.entries) {
          if (!isPaddingEntry(e.index)) {
            out.push_back(
                {sl.position, sm.outputs, bit, e.bitLength, e.index, e.subindex, pdo.name, e.name});
          }
          bit += e.bitLength;
        }
      }
    }
  }
  return out;
}

}  // namespace ecsim::master
