# Writes a copy of LighterGlue's ONNX graph that also outputs its log-assignment matrix (the scores before
# the mutual-best selection), so that make_reference.js can keep it as test data. Debian's python3-onnx.
#
#   /usr/bin/python3 tests/data/lighterglue/expose_scores.py OUT.onnx
import sys

import onnx

MODEL = "kernels/nn/models/lighterglue/lighterglue_L3.onnx"
SCORES = "/net/log_assignment.2/Add_2_output_0"

model = onnx.load(MODEL)
model.graph.output.append(onnx.helper.make_tensor_value_info(SCORES, onnx.TensorProto.FLOAT, None))
onnx.save(model, sys.argv[1])
