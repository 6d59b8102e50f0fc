// Image error metrics for the quality benchmark: RMSE, PSNR and SSIM of two
// pictures, and the integer resampling that brings pictures of different
// sizes onto one grid. Header-only and VTK-free (the benchmark runs on a GPU
// machine with only CUDA, CMake and a compiler).
//
// What is compared: the engine's premultiplied RGB, that is the picture
// over a black background, each channel clamped to [0, 1] (the range a
// display shows), so the data range L of PSNR and SSIM is 1. Alpha is not
// compared separately: over black it is already in the colour.
//
// SSIM follows Wang, Bovik, Sheikh and Simoncelli, "Image quality
// assessment: from error visibility to structural similarity", IEEE TIP 13
// (2004): local means, variances and covariance under an 11x11 Gaussian
// window of sigma 1.5 (normalised, population statistics), K1 = 0.01,
// K2 = 0.03, averaged over the pixels whose window lies inside the picture;
// computed per RGB channel and the three means averaged. That is
// scikit-image's structural_similarity(a, b, channel_axis=-1, data_range=1,
// gaussian_weights=True, sigma=1.5, use_sample_covariance=False), which
// Testing/Python/test_bench_quality_metrics.py checks against.
#pragma once

#include <octoray/Render.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace octoray
{
namespace bench
{
// Three floats a pixel in [0, 1], rows from the bottom (as Image).
struct RgbImage
{
  int width = 0, height = 0;
  std::vector<float> rgb;

  float At(int x, int y, int c) const { return rgb[3 * (static_cast<std::size_t>(y) * width + x) + c]; }
};

inline RgbImage ToRgb(const Image& image)
{
  RgbImage out;
  out.width = image.width;
  out.height = image.height;
  const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  out.rgb.resize(3 * pixels);
  for (std::size_t i = 0; i < pixels; ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      const float v = image.rgba[4 * i + c];
      out.rgb[3 * i + c] = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v); // also maps NaN to 0
    }
  }
  return out;
}

// Each pixel repeated factor x factor times: what a viewer showing a picture
// rendered at a lower resolution on the full-size screen shows (nearest).
inline RgbImage UpsampleNearest(const RgbImage& in, int factor)
{
  RgbImage out;
  out.width = in.width * factor;
  out.height = in.height * factor;
  out.rgb.resize(3 * static_cast<std::size_t>(out.width) * out.height);
  for (int y = 0; y < out.height; ++y)
  {
    for (int x = 0; x < out.width; ++x)
    {
      for (int c = 0; c < 3; ++c)
      {
        out.rgb[3 * (static_cast<std::size_t>(y) * out.width + x) + c] = in.At(x / factor, y / factor, c);
      }
    }
  }
  return out;
}

// The mean of each factor x factor block: a supersampled picture (factor^2
// rays a pixel on a regular grid) brought down to the display's size.
inline RgbImage DownsampleBox(const RgbImage& in, int factor)
{
  if (in.width % factor || in.height % factor)
  {
    throw std::runtime_error("DownsampleBox: size not a multiple of the factor");
  }
  RgbImage out;
  out.width = in.width / factor;
  out.height = in.height / factor;
  out.rgb.assign(3 * static_cast<std::size_t>(out.width) * out.height, 0.0f);
  const double scale = 1.0 / (factor * factor);
  for (int y = 0; y < out.height; ++y)
  {
    for (int x = 0; x < out.width; ++x)
    {
      for (int c = 0; c < 3; ++c)
      {
        double sum = 0;
        for (int j = 0; j < factor; ++j)
        {
          for (int i = 0; i < factor; ++i)
          {
            sum += in.At(factor * x + i, factor * y + j, c);
          }
        }
        out.rgb[3 * (static_cast<std::size_t>(y) * out.width + x) + c] = static_cast<float>(sum * scale);
      }
    }
  }
  return out;
}

inline void CheckSameSize(const RgbImage& a, const RgbImage& b)
{
  if (a.width != b.width || a.height != b.height)
  {
    throw std::runtime_error("image metrics: pictures of different sizes (" + std::to_string(a.width) + "x" +
      std::to_string(a.height) + " and " + std::to_string(b.width) + "x" + std::to_string(b.height) + ")");
  }
}

// Mean squared error over every channel of every pixel.
inline double MeanSquaredError(const RgbImage& a, const RgbImage& b)
{
  CheckSameSize(a, b);
  double sum = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i)
  {
    const double d = double(a.rgb[i]) - double(b.rgb[i]);
    sum += d * d;
  }
  return a.rgb.empty() ? 0.0 : sum / a.rgb.size();
}

inline double Rmse(const RgbImage& a, const RgbImage& b)
{
  return std::sqrt(MeanSquaredError(a, b));
}

// 10 log10(L^2 / MSE) with L = 1; +infinity for identical pictures.
inline double Psnr(const RgbImage& a, const RgbImage& b)
{
  const double mse = MeanSquaredError(a, b);
  return mse > 0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
}

namespace detail
{
constexpr int kSsimRadius = 5; // 11 taps: int(3.5 sigma + 0.5) as scipy.ndimage truncates
constexpr double kSsimSigma = 1.5;

// Gaussian filter of one plane (row-major, w x h) in "valid" mode: the
// output holds the (w - 10) x (h - 10) pixels whose whole window is inside.
// Separable: rows, then columns.
inline std::vector<double> GaussianValid(const std::vector<double>& in, int w, int h, const double* kernel)
{
  const int r = kSsimRadius, ow = w - 2 * r, oh = h - 2 * r;
  std::vector<double> rows(static_cast<std::size_t>(ow) * h);
  for (int y = 0; y < h; ++y)
  {
    for (int x = 0; x < ow; ++x)
    {
      double s = 0;
      for (int k = 0; k <= 2 * r; ++k)
      {
        s += kernel[k] * in[static_cast<std::size_t>(y) * w + x + k];
      }
      rows[static_cast<std::size_t>(y) * ow + x] = s;
    }
  }
  std::vector<double> out(static_cast<std::size_t>(ow) * oh);
  for (int y = 0; y < oh; ++y)
  {
    for (int x = 0; x < ow; ++x)
    {
      double s = 0;
      for (int k = 0; k <= 2 * r; ++k)
      {
        s += kernel[k] * rows[static_cast<std::size_t>(y + k) * ow + x];
      }
      out[static_cast<std::size_t>(y) * ow + x] = s;
    }
  }
  return out;
}
}

// Mean SSIM (Wang et al. 2004), per RGB channel, channels averaged. Throws
// for pictures smaller than the 11x11 window.
inline double Ssim(const RgbImage& a, const RgbImage& b)
{
  CheckSameSize(a, b);
  const int r = detail::kSsimRadius, w = a.width, h = a.height;
  if (w < 2 * r + 1 || h < 2 * r + 1)
  {
    throw std::runtime_error("SSIM: pictures smaller than the 11x11 window");
  }
  double kernel[2 * detail::kSsimRadius + 1], total = 0;
  for (int k = -r; k <= r; ++k)
  {
    total += kernel[k + r] = std::exp(-0.5 * k * k / (detail::kSsimSigma * detail::kSsimSigma));
  }
  for (double& k : kernel)
  {
    k /= total;
  }
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03; // (K1 L)^2, (K2 L)^2 with L = 1
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  double channelSum = 0;
  for (int c = 0; c < 3; ++c)
  {
    std::vector<double> x(pixels), y(pixels), xx(pixels), yy(pixels), xy(pixels);
    for (std::size_t i = 0; i < pixels; ++i)
    {
      x[i] = a.rgb[3 * i + c];
      y[i] = b.rgb[3 * i + c];
      xx[i] = x[i] * x[i];
      yy[i] = y[i] * y[i];
      xy[i] = x[i] * y[i];
    }
    const std::vector<double> mx = detail::GaussianValid(x, w, h, kernel);
    const std::vector<double> my = detail::GaussianValid(y, w, h, kernel);
    const std::vector<double> mxx = detail::GaussianValid(xx, w, h, kernel);
    const std::vector<double> myy = detail::GaussianValid(yy, w, h, kernel);
    const std::vector<double> mxy = detail::GaussianValid(xy, w, h, kernel);
    double sum = 0;
    for (std::size_t i = 0; i < mx.size(); ++i)
    {
      const double vx = mxx[i] - mx[i] * mx[i], vy = myy[i] - my[i] * my[i], vxy = mxy[i] - mx[i] * my[i];
      sum += ((2 * mx[i] * my[i] + c1) * (2 * vxy + c2)) / ((mx[i] * mx[i] + my[i] * my[i] + c1) * (vx + vy + c2));
    }
    channelSum += sum / mx.size();
  }
  return channelSum / 3;
}

// Portable float map (PFM, colour): "PF", size, -1 (little-endian), then
// rows from the bottom, which is the order Image keeps. Lossless, so a
// checker reads exactly the floats the metrics saw.
inline void WritePfm(const std::string& path, const RgbImage& image)
{
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f)
  {
    throw std::runtime_error(path + ": cannot be written");
  }
  std::fprintf(f, "PF\n%d %d\n-1.0\n", image.width, image.height);
  const std::size_t n = image.rgb.size();
  const bool ok = std::fwrite(image.rgb.data(), sizeof(float), n, f) == n; // little-endian hosts only
  if (std::fclose(f) != 0 || !ok)
  {
    throw std::runtime_error(path + ": write failed");
  }
}
}
}
