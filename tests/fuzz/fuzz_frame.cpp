// libFuzzer target: arbitrary bytes as an Ethernet frame. A frame that parses is walked datagram
// by datagram through both the mutable and the const view, every field is read, and each
// datagram's data is offered to the mailbox decoders (a mailbox datagram carries a whole
// SyncManager buffer).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "protocol/frame.hpp"
#include "tests/fuzz/mailbox_checks.hpp"

namespace {

using ecsim::fuzz::require;

template <typename Frame>
void walk(const Frame& frame) {
  std::size_t count = 0;
  std::size_t bytes = 0;
  std::uint64_t sink = 0;
  for (auto it = frame.begin(); it != frame.end(); ++it) {
    auto d = *it;
    const ecsim::DatagramHeader h = d.header();
    require(h.length == d.length() && h.more == d.more() && h.circulating == d.circulating());
    require(h.command == d.command() && h.index == d.index() && h.address == d.address());
    require(h.adp() == d.adp() && h.ado() == d.ado() && h.irq == d.irq());
    require(d.bytes().size() == h.wireSize());
    sink += d.rawCommand() + d.wkc() + static_cast<unsigned>(ecsim::isKnownCommand(d.rawCommand()));
    if (ecsim::isKnownCommand(d.rawCommand())) {
      sink += ecsim::toString(d.command()).size();
      sink += static_cast<unsigned>(ecsim::addressMode(d.command()));
      sink += ecsim::commandAccess(d.command()).read ? 1u : 0u;
    }
    for (std::uint8_t b : d.data()) sink += b;
    ecsim::fuzz::checkMailboxBuffer(d.data());
    bytes += h.wireSize();
    ++count;
    require(count <= frame.datagramCount());
  }
  require(count == frame.datagramCount());
  require(bytes == frame.datagramBytes());
  require(frame.datagramsOffset() + bytes <= frame.frame().size());
  volatile std::uint64_t keep = sink;
  (void)keep;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> buffer(data, data + size);
  if (auto frame = ecsim::EtherCatFrame::parse(buffer)) {
    walk(*frame);
    // The simulator writes in place: WKC and circulating bit must stay inside the datagram.
    for (auto d : *frame) {
      d.setWkc(static_cast<std::uint16_t>(d.wkc() + 1));
      d.setCirculating(!d.circulating());
    }
    auto again = ecsim::EtherCatFrame::parse(buffer);
    require(again.ok() && again->datagramCount() == frame->datagramCount());
  }
  if (auto frame = ecsim::ConstEtherCatFrame::parse(ecsim::ConstBytes(data, size))) walk(*frame);
  return 0;
}
