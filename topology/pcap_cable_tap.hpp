// A CableObserver that writes what it sees to a pcap file, stamped with model time plus a
// fixed offset (for example the Unix time of model time 0, or the DC epoch for deterministic
// captures). This is how `--pcap` (the master's cable) and `--pcap-link NAME=FILE` (any
// cable) capture: the stamps follow the timing model, not the host's scheduling.
#pragma once

#include "link/pcap.hpp"
#include "topology/segment.hpp"

namespace ecsim::topology {

class PcapCableTap final : public CableObserver {
 public:
  PcapCableTap(PcapWriter& writer, SimTime offset) : writer_(writer), offset_(offset) {}

  void onFrame(ConstBytes frame, SimTime time, bool /*downstream*/) override {
    if (auto s = writer_.write(frame, time + offset_); !s.ok() && firstError_.ok()) {
      firstError_ = s;
    }
  }
  // The first write error, if any (a capture problem never disturbs the network).
  const Status& status() const { return firstError_; }

 private:
  PcapWriter& writer_;
  SimTime offset_;
  Status firstError_{};
};

}  // namespace ecsim::topology
