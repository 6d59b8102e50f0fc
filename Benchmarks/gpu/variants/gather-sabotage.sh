# The staged records test against a sabotaged gather (Benchmarks/gpu/engine-tests-sort-during-upload.txt):
# run from the repository root on the GPU machine, with .gpu-vtk/googletest carried. The gather of the
# records in sorted order (OctreeDriver.h's GatherSortedRecords) leaves out the last point; the CUDA
# run of RecordsOfEveryWidth, whose staged clouds take that path, must fail.
set -x
S=/root/sab; B=/root/sab-build; G=$PWD/.gpu-vtk/googletest
mkdir -p $S && tar cf - --exclude=./build-gpu --exclude=./.gpu-vtk --exclude=./build --exclude=./build-vtk-egl . | tar xf - -C $S
H=$S/Rendering/Engine/octoray/OctreeDriver.h
sed -i 's/d.ForEach("GatherRecordsKernel", pts.count,/d.ForEach("GatherRecordsKernel", pts.count - 1,/' $H
diff Rendering/Engine/octoray/OctreeDriver.h $H
cmake -S $S/Rendering/Engine -B $B -G Ninja -DCMAKE_CUDA_ARCHITECTURES=90 -DOCTORAY_ENABLE_CUDA=ON -DOCTORAY_GTEST_SOURCE_DIR=$G > /dev/null && ninja -C $B octoray_engine_tests > /dev/null && $B/bin/octoray_engine_tests --gtest_filter='*RecordsOfEveryWidth*' 2>&1 | grep -E "^\[ +(OK|FAILED|PASSED) +\]|tests ran|Failure|staged" | head -40
