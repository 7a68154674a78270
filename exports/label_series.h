#pragma once
// The labels of one labeling job in frame order: what every export reads. One job
// labels one hand, so the series has one side and one hand model.

#include <string>
#include <vector>

#include "pipeline/label_record.h"

namespace handlabel {

struct LabelSeries {
  std::string labels_dir;           // the folder the label files were read from
  std::vector<LabelRecord> labels;  // sorted by frame id (the capture's frame order)
  HandSide side = HandSide::kRight;
  std::string hand_model;  // provenance.hand_model, the same in every label

  // The label file `frame` was read from, for messages.
  std::string FileOf(const std::string& frame) const;
};

// Reads every labels/<frame>.json of a job's output folder (`dir` may be the output
// folder or its labels/ folder). Throws InputError naming the folder when it holds no
// label, or naming the file whose side or hand model differs from the first label's.
LabelSeries ReadLabelSeries(const std::string& dir);

}  // namespace handlabel
