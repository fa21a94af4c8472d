// A device with several CiA 402 axes (ETG.6010 multi-axis layout: axis n has its profile
// objects at 0x6000-0x67FF + n * 0x800): one Cia402Drive per axis over the one dictionary,
// each stepped and synchronised in axis order. Each axis has its own motor, encoder and
// emergencies; a state file, when given, is axis 0's.
#pragma once

#include <memory>
#include <vector>

#include "slavesim/devices/cia402_drive.hpp"

namespace ecsim::slavesim::devices {

class MultiAxisDrive final : public Application {
 public:
  explicit MultiAxisDrive(std::vector<std::unique_ptr<Cia402Drive>> axes)
      : axes_(std::move(axes)) {}

  void step(coe::ObjectDictionary& od, AlState state, SimTime now) override {
    for (auto& a : axes_) {
      a->setSyncActive(syncActive());
      a->step(od, state, now);
    }
  }
  void sync(coe::ObjectDictionary& od, unsigned signal, AlState state, SimTime now) override {
    for (auto& a : axes_) {
      a->setSyncActive(syncActive());
      a->sync(od, signal, state, now);
    }
  }

  std::size_t axes() const { return axes_.size(); }
  Cia402Drive& axis(std::size_t n) { return *axes_[n]; }
  void setEmergencySink(const EmergencySink& sink) {
    for (auto& a : axes_) a->setEmergencySink(sink);
  }

 private:
  std::vector<std::unique_ptr<Cia402Drive>> axes_;
};

}  // namespace ecsim::slavesim::devices
