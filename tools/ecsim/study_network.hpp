// `ecsim study latency --topology FILE`: what cycle time a given network (a topology file or
// an ENI) reaches with our master. The model: the network built in process, brought to OP by
// our master on virtual time (its process image from the devices' SII/CoE mapping, DC when a
// device has it), the master's cyclic frames carried through the segment
// (topology/latency_model.hpp). The measurement: the same master over a veth pair in a private
// namespace against `ecsim serve --paced` of the same file, once per cycle-time candidate.
// Output: latency.csv (one row per candidate), devices.csv (one row per device), latency.gp
// and latency.png.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "protocol/result.hpp"
#include "protocol/time.hpp"
#include "topology/latency_model.hpp"

namespace ecsim::tools::study {

struct NetworkStudyOptions {
  std::string topology;  // topology file or ENI
  std::string esiDir;    // the ESI folder of an ENI's devices (default: the ENI's folder)
  std::string out{"latency-study"};
  std::vector<double> cyclesUs{2000, 1000, 500, 250, 125, 62.5};
  double measureSeconds{2.0};  // per candidate
  bool measure{true};
  bool dc{true};            // use distributed clocks when a device has them
  std::string ecsimBinary;  // for `ecsim serve` (default: this program)
  // An external master, run per candidate after ours, in the namespace through `sh -c`, with
  // {iface} (the master's end of the pair), {netns}, {cycle_us} and {seconds} replaced. Its
  // standard output is read as `ecmaster --json cyclic` writes it (roundTripUs and jitterUs
  // with p50/p99/max, cycles, framesLost, framesLate, overruns, wkcErrors; any may be absent).
  std::string masterCommand;
};

struct DeviceRow {
  std::size_t position{0};  // bus position
  std::string name;
  std::uint32_t outputBytes{0};
  std::uint32_t inputBytes{0};
  SimTime processingNs{0};
  SimTime forwardingNs{0};
  bool dc{false};
};

struct NetworkModel {
  std::string name;
  std::vector<DeviceRow> devices;
  std::uint32_t outputBytes{0};
  std::uint32_t inputBytes{0};
  bool dc{false};  // the cyclic frame carries the reference clock's FRMW of 0x0910
  std::vector<topology::ModelFrame> frames;
  topology::ModelledCycle cycle;
};

// True for an ENI (<EtherCATConfig>): the master then also loads it as its configuration.
bool isEniFile(const std::string& path);

// Builds the network of options.topology, brings it to OP with our master on virtual time and
// models its cycle. Errors name the file.
Result<NetworkModel> modelNetwork(const NetworkStudyOptions& options);

struct MeasuredCycle {
  SimTime cycleNs{0};
  std::uint64_t cycles{0};
  SimTime rttP50{0}, rttP99{0}, rttMax{0};
  SimTime jitterP50{0}, jitterP99{0}, jitterMax{0};
  std::uint64_t lost{0}, late{0}, overruns{0}, wkcErrors{0};
  // An external master's figures: what its output gave (-1: not given), its exit status.
  int exitCode{0};
};

struct Measurement {
  std::vector<MeasuredCycle> ours;      // one per candidate
  std::vector<MeasuredCycle> external;  // one per candidate with --master-command, else none
};

// An external master's `ecmaster --json`-style output into figures (absent ones -1).
MeasuredCycle parseMasterJson(const std::string& output, SimTime cycleNs);

// One line of progress on stderr: redrawn in place on a terminal, plain lines otherwise (then
// only what `important` marks, so a log does not fill with redraws).
class Progress {
 public:
  Progress();
  void update(const std::string& line, bool important = false);
  void finish();

 private:
  bool tty_{false};
  bool open_{false};
};

// The measured curve (study_measure.cpp): needs CAP_NET_ADMIN, CAP_NET_RAW, CAP_SYS_ADMIN.
Result<Measurement> measureNetwork(const NetworkStudyOptions& options, const NetworkModel& model,
                                   Progress& progress);

// The SYNC0 shift a cycle needs after its start: the outputs complete at every slave, later by
// the master's send jitter (p99) when measured.
SimTime sync0Shift(const NetworkModel& model, const MeasuredCycle* measured);

// external.csv's header and one row.
std::string externalCsvHeader();
std::string externalCsvRow(double cycleUs, const MeasuredCycle& m);

// latency.csv's header and one row (measured: nullptr when not measured).
std::string csvHeader();
std::string csvRow(double cycleUs, const NetworkModel& model, const MeasuredCycle* measured);

// latency.gp for the candidates (x range fitted to them, reference lines at 1 ms, 500, 250 and
// 125 us where they fall inside), with the measured curves when `measured`.
std::string gnuplotScript(const NetworkModel& model, const std::vector<double>& cyclesUs,
                          bool measured, bool external = false);

// The whole study; the process exit code (errors printed).
int runNetworkStudy(const NetworkStudyOptions& options);

}  // namespace ecsim::tools::study
