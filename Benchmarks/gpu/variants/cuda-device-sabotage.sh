# The CUDA device checks against a sabotaged CudaDevice.h (Benchmarks/gpu/engine-tests-cuda-device.txt):
# run from the repository root on the GPU machine, with .gpu-vtk/googletest carried.
set -x
S=/root/sab; B=/root/sab-build; G=$PWD/.gpu-vtk/googletest
mkdir -p $S && tar cf - --exclude=./build-gpu --exclude=./.gpu-vtk --exclude=./build --exclude=./build-vtk-egl . | tar xf - -C $S
H=$S/Rendering/Engine/octoray/CudaDevice.h
sed -i '47s/if (i < n)/if (i + 1 < n)/; 125s/i < n ? firstList(i)/i + 1 < n ? firstList(i)/; s/count, n, selected)/count, n - (n > 0), selected)/; s/k, v, n, 0, bits)/k, v, n, 0, bits - 1)/; s/k, n, 0, bits)/k, n, 0, bits - 1)/' $H
diff Rendering/Engine/octoray/CudaDevice.h $H
cmake -S $S/Rendering/Engine -B $B -G Ninja -DCMAKE_CUDA_ARCHITECTURES=90 -DOCTORAY_ENABLE_CUDA=ON -DOCTORAY_GTEST_SOURCE_DIR=$G > /dev/null && ninja -C $B octoray_engine_tests > /dev/null && $B/bin/octoray_engine_tests --gtest_filter='CudaDeviceCUDA*' 2>&1 | grep -E "^\[ +(OK|FAILED|PASSED) +\]|tests ran"
