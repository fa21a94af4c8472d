// libFuzzer target: arbitrary bytes straight into the mailbox, CoE, SDO and SDO-information
// decoders (as one SyncManager buffer, as a run of consecutive mailboxes, and as service data
// to split into fragments and join again).
#include <cstddef>
#include <cstdint>

#include "tests/fuzz/mailbox_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const ecsim::ConstBytes in(data, size);
  ecsim::fuzz::checkMailboxBuffer(in);
  ecsim::fuzz::checkReassembly(in);
  ecsim::fuzz::checkFragmentation(in);
  // SDO bodies on their own (the bytes after a CoE header).
  (void)ecsim::decodeSdoRequest(in);
  (void)ecsim::decodeSdoResponse(in);
  return 0;
}
