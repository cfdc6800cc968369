// RecordPipe: records reach the writer thread complete and in order, and a writer's
// failure comes back to the producer instead of being lost.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "wheelins/io/record_pipe.hpp"
#include "wheelins/nav/types.hpp"

using namespace wheelins;

TEST(IoRecordPipe, EveryRecordArrivesInOrder) {
  std::vector<std::pair<int, double>> seen;
  {
    RecordPipe pipe([&](int stream, const TrajectoryRecord& r) { seen.emplace_back(stream, r.t); },
                    64, 3);
    for (int i = 0; i < 10007; ++i) {  // not a multiple of the batch: a partial last batch
      TrajectoryRecord r;
      r.t = i;
      pipe.push(i % 4, r);
    }
    pipe.finish();
  }
  ASSERT_EQ(seen.size(), 10007u);
  for (int i = 0; i < 10007; ++i) {
    EXPECT_EQ(seen[i].first, i % 4);
    EXPECT_EQ(seen[i].second, i);
  }
}

TEST(IoRecordPipe, WriterFailureReachesTheProducer) {
  int consumed = 0;
  RecordPipe pipe(
      [&](int, const TrajectoryRecord& r) {
        if (r.t >= 500) throw InputError("'out.csv': No space left on device");
        ++consumed;
      },
      16, 2);
  bool thrown = false;
  try {
    for (int i = 0; i < 100000; ++i) {
      TrajectoryRecord r;
      r.t = i;
      pipe.push(0, r);
    }
    pipe.finish();
  } catch (const InputError& e) {
    thrown = true;
    EXPECT_NE(std::string(e.what()).find("out.csv"), std::string::npos);
  }
  EXPECT_TRUE(thrown);
  EXPECT_EQ(consumed, 500);
}

TEST(IoRecordPipe, FinishWithoutRecordsAndDestructionWithoutFinish) {
  int n = 0;
  { RecordPipe pipe([&](int, const TrajectoryRecord&) { ++n; }); }  // no finish(): joins quietly
  RecordPipe pipe([&](int, const TrajectoryRecord&) { ++n; });
  pipe.finish();
  EXPECT_EQ(n, 0);
}
