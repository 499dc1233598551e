#include "core/pipeline/stage_record.h"

#include <cstdio>
#include <set>
#include <sstream>

#include "core/base/atomic_file.h"

namespace reconar {

StageRecord::StageRecord(const Project& project) : path_(project.root() + "/stages.txt") { Read(); }

void StageRecord::Read() {
  stages_.clear();
  auto text = ReadFileToString(path_);
  if (!text.ok()) return;
  std::istringstream in(*text);
  std::string line;
  while (std::getline(in, line)) {
    const size_t space = line.find(' ');
    if (space != std::string::npos) stages_[line.substr(0, space)] = line.substr(space + 1);
  }
}

bool StageRecord::Finished(const std::string& stage, const std::string& settings) const {
  const auto it = stages_.find(stage);
  return it != stages_.end() && it->second == settings;
}

Status StageRecord::Record(const std::string& stage, const std::string& settings) {
  Read();
  stages_[stage] = settings;
  std::set<std::string> replaced = {stage};
  for (bool grew = true; grew;) {  // the stages reading a replaced one, until none is added
    grew = false;
    for (const StageInputs& reader : kStageInputs) {
      if (replaced.count(reader.stage) != 0) continue;
      for (const char* input : reader.inputs) {
        if (input == nullptr || replaced.count(input) == 0) continue;
        replaced.insert(reader.stage);
        stages_.erase(reader.stage);
        grew = true;
        break;
      }
    }
  }
  std::string text;
  for (const auto& [name, value] : stages_) text += name + " " + value + "\n";
  return WriteFileAtomically(path_, text);
}

std::string StageRecord::Settings(std::initializer_list<std::pair<const char*, double>> values) {
  std::string text;
  char buffer[64];
  for (const auto& [name, value] : values) {
    std::snprintf(buffer, sizeof(buffer), "%s%s=%.12g", text.empty() ? "" : " ", name, value);
    text += buffer;
  }
  return text;
}

}  // namespace reconar
