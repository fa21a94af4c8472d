// Process data of a dictionary-based slave: from the PDO assignment (0x1C10+n) and mapping
// objects (0x16xx/0x1Axx) currently in the object dictionary, the layout of every process-data
// SyncManager (what SM2/SM3 lengths the slave expects, fed to the ESM before PREOP->SAFEOP so
// a wrong length gives AL status 0x001D/0x001E), and the cyclic copy between SM buffers and
// object values:
//   outputs (SM type 3 in 0x1C00): the newest complete SM buffer is copied bit by bit into the
//            values of the mapped RxPDO entries;
//   inputs  (SM type 4): the mapped TxPDO entries' values are packed into the SM buffer.
// Entries are packed LSB first in mapping order with no alignment (a gap entry, index 0, just
// advances the offset), exactly as a master computes offsets from the same objects.
//
// Slaves without CoE (SII-only, e.g. an EL2004) use the same code with a dictionary built from
// their ESI PDOs that no mailbox reaches.
//
// bind() allocates (done at PREOP->SAFEOP, off the cyclic path); readOutputs() and
// writeInputs() never allocate.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "protocol/result.hpp"
#include "slavesim/coe/object_dictionary.hpp"
#include "slavesim/coe/standard_objects.hpp"
#include "slavesim/slave.hpp"

namespace ecsim::slavesim {

struct ProcessDataSmLayout {
  unsigned sm{0};
  bool outputs{true};
  std::uint32_t bitLength{0};
  std::vector<coe::MappedObject> entries;  // in SM order, gaps included
  std::uint16_t byteLength() const { return static_cast<std::uint16_t>((bitLength + 7) / 8); }
};

// The layout the current assignment and mappings give. Errors name the object that makes the
// configuration unusable (an assigned PDO that does not exist, a mapped entry that does not
// exist or is shorter than its mapping).
Result<std::vector<ProcessDataSmLayout>> computeProcessDataLayout(const coe::ObjectDictionary& od);

class ProcessDataBinding {
 public:
  // Recomputes the layout and the copy plan; the dictionary must outlive the binding and keep
  // its objects (values may change, objects must not be replaced) until the next bind().
  // On error the binding is empty (no SM expected, nothing copied). SMs in `skip` (bit n =
  // SM n) are laid out but not copied.
  Status bind(coe::ObjectDictionary& od, std::uint32_t skip = 0);
  const std::vector<ProcessDataSmLayout>& layout() const { return layout_; }
  // Replaces profile.processData with the expected SM lengths, leaving out the SMs in
  // `unchecked` (bit n = SM n).
  void fillProfile(SlaveProfile& profile, std::uint32_t unchecked = 0) const;

  // Cyclic path (no allocation). readOutputs copies only SMs the master has written at least
  // once; writeInputs writes every input SM.
  void readOutputs(Esc& esc);
  void writeInputs(Esc& esc);

 private:
  struct Copy {
    std::size_t buffer{0};       // index into buffers_
    std::uint32_t bitOffset{0};  // in the SM
    std::uint16_t bits{0};
    std::uint8_t* value{nullptr};  // the entry's value bytes
    std::size_t valueSize{0};
  };
  struct Buffer {
    unsigned sm{0};
    bool outputs{true};
    std::vector<std::uint8_t> bytes;
  };
  std::vector<ProcessDataSmLayout> layout_;
  std::vector<Buffer> buffers_;
  std::vector<Copy> copies_;
};

// A device model that works on the object dictionary: called each firmware step between the
// output copy and the input copy.
class Application {
 public:
  virtual ~Application() = default;
  virtual void step(coe::ObjectDictionary& od, AlState state, SimTime now) = 0;
  // A SYNC0/SYNC1 pulse (Device::sync), between the same output and input copies. While
  // syncActive() an application synchronised to DC does its cycle here rather than in step().
  virtual void sync(coe::ObjectDictionary& /*od*/, unsigned /*signal*/, AlState /*state*/,
                    SimTime /*now*/) {}
  // Whether the ESC generates SYNC0 (Esc::syncActive(0)), set before each step() and sync().
  bool syncActive() const { return syncActive_; }
  void setSyncActive(bool active) { syncActive_ = active; }

 private:
  bool syncActive_{false};
};

// The Device of a dictionary-based slave: keeps the ESM's expectations up to date (rebinding
// at every AL control write, so a PDO assignment changed in PREOP counts at PREOP->SAFEOP),
// and in SAFEOP and OP copies outputs -> dictionary, runs the application, copies dictionary
// -> inputs. Outputs are copied in SAFEOP too (the values an application sees are the newest
// the master sent); an application decides itself what SAFEOP means for its actuators.
//
// Power cycle (coldStart): the dictionary goes back to its power-up values, taken when the
// firmware first ran (powerUp; so the values a builder or a topology <Input> set count as power-up
// values; what the master wrote since does not), the binding follows the restored PDO
// assignment and mapping, and the restart function, when set, re-creates the application.
class ProcessDataDevice final : public Device {
 public:
  explicit ProcessDataDevice(std::shared_ptr<coe::ObjectDictionary> od);

  void updateProfile(SlaveProfile& profile) override;
  void step(Esc& esc, AlState state, SimTime now) override;
  void sync(Esc& esc, unsigned signal, AlState state, SimTime now) override;
  void powerUp() override;
  Status coldStart() override;

  // Re-creates the application after a power cycle (devices::restartDeviceModel).
  using Restart = std::function<Status(ProcessDataDevice&)>;
  void setRestart(Restart restart) { restart_ = std::move(restart); }

  coe::ObjectDictionary& dictionary() { return *od_; }
  std::shared_ptr<coe::ObjectDictionary> sharedDictionary() { return od_; }
  const ProcessDataBinding& binding() const { return binding_; }
  // The outcome of the last bind (an unusable PDO configuration is reported here).
  const Status& bindStatus() const { return bindStatus_; }
  // SMs the ESM does not check and the binding does not copy (bit n = SM n): ESI "Virtual"
  // SMs, through which a master maps ESC registers (EL1252: latch status 0x09AE, system time
  // 0x0910) rather than buffers the firmware fills.
  void setVirtualSyncManagers(std::uint32_t mask) { virtualSms_ = mask; }
  void setApplication(std::unique_ptr<Application> application) {
    application_ = std::move(application);
  }
  Application* application() { return application_.get(); }

 private:
  std::shared_ptr<coe::ObjectDictionary> od_;
  ProcessDataBinding binding_;
  Status bindStatus_;
  std::uint32_t virtualSms_{0};
  std::unique_ptr<Application> application_;
  Restart restart_;
};

}  // namespace ecsim::slavesim
