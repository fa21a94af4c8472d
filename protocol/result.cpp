#include "protocol/result.hpp"

namespace ecsim {

std::string_view toString(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidArgument:
      return "invalid argument";
    case ErrorCode::kTruncated:
      return "truncated";
    case ErrorCode::kTooLarge:
      return "too large";
    case ErrorCode::kMalformed:
      return "malformed";
    case ErrorCode::kNotFound:
      return "not found";
    case ErrorCode::kUnsupported:
      return "unsupported";
    case ErrorCode::kIo:
      return "I/O error";
    case ErrorCode::kPermission:
      return "permission denied";
    case ErrorCode::kTimeout:
      return "timeout";
    case ErrorCode::kWorkingCounter:
      return "working counter mismatch";
    case ErrorCode::kState:
      return "wrong state";
    case ErrorCode::kAborted:
      return "aborted";
    case ErrorCode::kParse:
      return "parse error";
  }
  return "unknown error";
}

}  // namespace ecsim
