// Test helpers shared by the navigation tests: a navigator fed from a dataset's files.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "wheelins/fusion/navigator.hpp"
#include "wheelins/io/imu_file.hpp"
#include "wheelins/io/manifest.hpp"

namespace wheelins::test {

// Feeds `modules`' samples (merged by time) to `navigator` while their time is below t_end.
inline void replay(Navigator& navigator, const Manifest& m, const std::vector<std::string>& modules,
                   double t_end = std::numeric_limits<double>::infinity()) {
  std::vector<std::unique_ptr<ImuStream>> readers;
  for (const auto& name : modules)
    readers.push_back(std::make_unique<ImuFileReader>(m.resolve(m.find(name)->file),
                                                      imu_read_options(*m.find(name))));
  ImuMerger merger(std::move(readers));
  std::size_t i = 0;
  ImuSample s;
  while (merger.next(i, s) && s.t < t_end) navigator.process(static_cast<int>(i), s);
}

}  // namespace wheelins::test
