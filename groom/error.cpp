#include "groom/error.h"

namespace plume {

std::string FileLoc::str() const {
  std::string s = file.empty() ? std::string("<input>") : file;
  if (line > 0) {
    s.append(":").append(std::to_string(line));
    if (column > 0) s.append(":").append(std::to_string(column));
  } else if (byte_offset >= 0) {
    s.append("@byte ").append(std::to_string(byte_offset));
  }
  return s;
}

}  // namespace plume
