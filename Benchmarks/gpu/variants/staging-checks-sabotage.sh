# The CUDA device's StageReduced and ReduceSmallLevels checks against a sabotaged engine
# (Benchmarks/gpu/variants-gather-staged.txt, call 2): run from the repository root on the GPU machine, with
# .gpu-vtk/googletest carried. SmallLevelsKernel reduces the levels from the root down, not from the one above the
# leaves up; the staged copy's afterFirst runs without the default stream waiting for the first array's pieces.
set -x
S=/root/sab2; B=/root/sab2-build; G=$PWD/.gpu-vtk/googletest
mkdir -p $S && tar cf - --exclude=./build-gpu --exclude=./.gpu-vtk --exclude=./build --exclude=./build-vtk-egl . | tar xf - -C $S
O=$S/Rendering/Engine/octoray
sed -i 's/for (int l = top; l >= 0; --l)/for (int l = 0; l <= top; ++l)/' $O/CudaDevice.h
sed -i 's/CudaCheck(cudaStreamWaitEvent(0, other.firstQueued, 0), what);/(void)other;/' $O/CudaUpload.h
diff -r Rendering/Engine/octoray $O
cmake -S $S/Rendering/Engine -B $B -G Ninja -DCMAKE_CUDA_ARCHITECTURES=90 -DOCTORAY_ENABLE_CUDA=ON -DOCTORAY_GTEST_SOURCE_DIR=$G > /dev/null && ninja -C $B octoray_engine_tests > /dev/null && $B/bin/octoray_engine_tests --gtest_filter='CudaDeviceCUDA*' 2>&1 | grep -E "^\[ +(OK|FAILED|PASSED) +\]|tests ran|Failure|whenReduced"
