// The logical process image and how it reaches the slaves:
//
//   layout    all outputs first (slave by slave, each SM byte-aligned), then all inputs;
//             process image offset = logical address - logicalBase
//   SMs       every process-data SM of the SII SM category: start and control byte from the
//             SII, length from the PDO mapping, enabled when the length is not 0
//   FMMUs     one per SM with data, outputs first (FMMU0...), logical range -> SM start,
//             type write for outputs, read for inputs
//   datagrams LRW over the image, split where a datagram would exceed what one frame
//             carries (at a slave's area boundary where possible, inside an area only when
//             the area alone is larger); each datagram's expected WKC is the sum over the
//             slaves it touches of 2 (outputs written) + 1 (inputs read), the ESC's rule of
//             counting per datagram, not per FMMU (notes/soem-interop.md §3.6); the slaves
//             it touches are kept to name them when the WKC is wrong
//   frames    datagrams packed in order into frames of at most 1514 bytes
//
// A master configured from an ENI with cyclic frames places the slaves and takes the datagrams
// from the ENI instead (master/eni_config.hpp: planEniLayout), into these same structures.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "master/batch.hpp"
#include "master/esc_config.hpp"
#include "master/pdo_config.hpp"
#include "master/slave_info.hpp"
#include "master/transport.hpp"
#include "protocol/al_status.hpp"
#include "protocol/frame.hpp"

namespace ecsim::master {

struct SmLayout {
  unsigned sm{0};
  bool outputs{true};
  SyncManagerBlock setting;
  std::uint32_t bitLength{0};
  std::uint32_t logicalStart{0};  // meaningful when setting.length > 0
  std::vector<PdoInfo> pdos;
};

struct SlaveLayout {
  std::size_t position{0};
  std::uint16_t station{0};
  std::vector<SmLayout> sms;
  std::vector<FmmuBlock> fmmus;  // FMMU n = fmmus[n]
  std::uint8_t fmmuCount{0};       // the ESC's FMMUs, all written (the unused ones cleared)
  std::uint32_t outputOffset{0};   // in the process image
  std::uint32_t outputBytes{0};
  std::uint32_t inputOffset{0};
  std::uint32_t inputBytes{0};
};

// AlState values as bits of LogicalDatagram::states.
constexpr std::uint8_t kAllStates = 0xFF;
constexpr std::uint8_t stateBit(AlState state) {
  // INIT 1, PREOP 2, SAFEOP 4, OP 8 are bits already; BOOT (3) gets a bit of its own.
  return state == AlState::kBootstrap ? std::uint8_t{0x10} : static_cast<std::uint8_t>(state);
}

struct LogicalDatagram {
  // The address field: the logical address of LRD/LWR/LRW, else ADP | ADO << 16.
  std::uint32_t logicalStart{0};
  std::uint16_t length{0};
  std::uint16_t expectedWkc{0};
  std::vector<std::size_t> slaves;  // positions of the slaves it touches
  // What each of `slaves` adds to the working counter (same order): the health monitor takes a
  // lost slave's share out of the expectation.
  std::vector<std::uint16_t> contributions;
  std::size_t frame{0};
  // planProcessImage() makes LRWs sent in every state. An ENI's cyclic Cmd may be any command
  // (master/eni_config.hpp): only logical ones exchange image bytes (outputs copied into the
  // frame for LWR/LRW, inputs copied out for LRD/LRW); the others carry their WKC only. It is
  // sent while the bus is in one of `states` (stateBit() values); checkWkc false: no <Cnt>.
  Command command{Command::kLrw};
  std::uint8_t states{kAllStates};
  bool checkWkc{true};
  int line{0};  // the ENI line of the Cmd, 0 when planned
  bool activeIn(AlState state) const { return (states & stateBit(state)) != 0; }
};

struct ProcessImageLayout {
  std::uint32_t logicalBase{0};
  std::uint32_t outputBytes{0};
  std::uint32_t inputBytes{0};
  std::vector<SlaveLayout> slaves;  // one per slave, in position order
  std::vector<LogicalDatagram> datagrams;
  std::size_t frameCount{0};

  std::uint32_t size() const { return outputBytes + inputBytes; }
};

struct LayoutOptions {
  std::uint32_t logicalBase{0};
  // Most data per datagram: what one untagged frame carries by default.
  std::size_t maxDatagramData{Transport::kMaxDatagramData};
};

// processData[i] belongs to slaves[i]. Errors name the slave: an SM the SII does not have, more
// FMMUs than the ESC has, an SM too long for its 16-bit length.
Result<ProcessImageLayout> planProcessImage(const std::vector<SlaveInfo>& slaves,
                                            const std::vector<SlaveProcessData>& processData,
                                            const LayoutOptions& options = {});

// One FMMU per SM with data, outputs first: logical range -> SM start, type write for outputs,
// read for inputs (after the SMs' logicalStart are set).
std::vector<FmmuBlock> fmmusOf(const SlaveLayout& slave);

// The SM and FMMU writes of the layout, one FPWR per SM and one per slave for its FMMUs.
void addProcessDataSetup(DatagramBatch& batch, const ProcessImageLayout& layout);

// Where each PDO entry lies in the process image: "Slave1.Out.Output 3" style names later.
struct ProcessVariable {
  std::size_t position{0};
  bool output{true};
  std::uint32_t bitOffset{0};  // in the process image
  std::uint8_t bitLength{0};
  std::uint16_t index{0};
  std::uint8_t subindex{0};
  std::string pdoName;
  std::string entryName;
};
std::vector<ProcessVariable> processVariables(const ProcessImageLayout& layout);

}  // namespace ecsim::master
