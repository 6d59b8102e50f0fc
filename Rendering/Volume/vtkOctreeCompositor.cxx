#include "vtkOctreeCompositor.h"

#include "vtkOctreeCudaInterop.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderUtilities.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include <octoray/Render.h>

#include <algorithm>

vtkOctreeCompositor::vtkOctreeCompositor()
  : Interop(new vtkOctreeCudaInterop)
{
}

vtkOctreeCompositor::~vtkOctreeCompositor()
{
  this->ReleaseGraphicsResources(this->Window);
}

//------------------------------------------------------------------------------
void vtkOctreeCompositor::UseWindow(vtkOpenGLRenderWindow* window)
{
  if (this->Window != window)
  {
    this->ReleaseGraphicsResources(this->Window);
    this->Window = window;
  }
}

//------------------------------------------------------------------------------
// The depth format of a multisampled source decides the resolve target's:
// a blit between depth buffers needs the same format.
static unsigned int DepthFormat(unsigned int drawFramebuffer)
{
  const GLenum attachment = drawFramebuffer == 0 ? GL_DEPTH : GL_DEPTH_ATTACHMENT;
  GLint bits = 24, type = GL_UNSIGNED_NORMALIZED, stencil = 0;
  glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, attachment, GL_FRAMEBUFFER_ATTACHMENT_DEPTH_SIZE, &bits);
  glGetFramebufferAttachmentParameteriv(
    GL_DRAW_FRAMEBUFFER, attachment, GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &type);
  glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, drawFramebuffer == 0 ? GL_STENCIL : GL_DEPTH_ATTACHMENT,
    GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE, &stencil);
  if (type == GL_FLOAT)
  {
    return stencil > 0 ? GL_DEPTH32F_STENCIL8 : GL_DEPTH_COMPONENT32F;
  }
  if (bits == 16)
  {
    return GL_DEPTH_COMPONENT16;
  }
  if (bits == 32)
  {
    return GL_DEPTH_COMPONENT32;
  }
  return stencil > 0 ? GL_DEPTH24_STENCIL8 : GL_DEPTH_COMPONENT24;
}

//------------------------------------------------------------------------------
// The base format and pixel type that go with a depth internal format, for
// allocating a texture of it.
static void DepthTextureFormat(unsigned int format, GLenum& base, GLenum& type)
{
  switch (format)
  {
    case GL_DEPTH24_STENCIL8:
      base = GL_DEPTH_STENCIL;
      type = GL_UNSIGNED_INT_24_8;
      return;
    case GL_DEPTH32F_STENCIL8:
      base = GL_DEPTH_STENCIL;
      type = GL_FLOAT_32_UNSIGNED_INT_24_8_REV;
      return;
    case GL_DEPTH_COMPONENT32F:
      base = GL_DEPTH_COMPONENT;
      type = GL_FLOAT;
      return;
    default:
      base = GL_DEPTH_COMPONENT;
      type = GL_UNSIGNED_INT;
  }
}

//------------------------------------------------------------------------------
// Makes or resizes the texture and its framebuffer for `width` x `height`
// depths of `format`. Leaves the draw framebuffer binding to the caller.
void vtkOctreeCompositor::DepthTarget::Fit(vtkOpenGLState* state, int width, int height, unsigned int format)
{
  if (this->Framebuffer && this->Size[0] == width && this->Size[1] == height && this->Format == format)
  {
    return;
  }
  if (!this->Framebuffer)
  {
    glGenFramebuffers(1, &this->Framebuffer);
    glGenTextures(1, &this->Texture);
  }
  GLenum base = GL_DEPTH_COMPONENT, type = GL_UNSIGNED_INT;
  DepthTextureFormat(format, base, type);
  glBindTexture(GL_TEXTURE_2D, this->Texture);
  glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(format), width, height, 0, base, type, nullptr);
  // Sampled texel for texel: no filtering, no mipmaps (without which the
  // texture would be incomplete), no comparison.
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_NONE);
  glBindTexture(GL_TEXTURE_2D, 0);
  state->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->Framebuffer);
  glFramebufferTexture2D(GL_DRAW_FRAMEBUFFER, base == GL_DEPTH_STENCIL ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT,
    GL_TEXTURE_2D, this->Texture, 0);
  this->Size[0] = width;
  this->Size[1] = height;
  this->Format = format;
}

//------------------------------------------------------------------------------
void vtkOctreeCompositor::DepthTarget::Release(bool withContext)
{
  if (withContext && this->Framebuffer)
  {
    glDeleteFramebuffers(1, &this->Framebuffer);
    glDeleteTextures(1, &this->Texture);
  }
  *this = DepthTarget();
}

//------------------------------------------------------------------------------
// Copies the viewport's depth from the framebuffer VTK draws into (a blit,
// which also resolves a multisampled one) into a single-sampled depth
// texture of the same format (a blit needs one), at the origin. The scissor
// test is off meanwhile: VTK scissors a renderer's viewport, which would
// keep the copy's corner from being written for a viewport away from the
// window's corner (the volume then drew as if everything lay in front of
// it). Returns the framebuffer that holds the copy; the draw and read
// bindings are as they were.
unsigned int vtkOctreeCompositor::CopyDepth(
  vtkOpenGLRenderWindow* window, unsigned int drawFramebuffer, int x0, int y0, int width, int height)
{
  vtkOpenGLState* state = window->GetState();
  const unsigned int format = DepthFormat(drawFramebuffer);
  vtkOpenGLState::ScopedglEnableDisable scissor(state, GL_SCISSOR_TEST);
  state->vtkglDisable(GL_SCISSOR_TEST);
  state->PushDrawFramebufferBinding();
  state->PushReadFramebufferBinding();
  this->Copy.Fit(state, width, height, format);
  state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, drawFramebuffer);
  state->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->Copy.Framebuffer);
  glBlitFramebuffer(x0, y0, x0 + width, y0 + height, 0, 0, width, height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
  state->PopReadFramebufferBinding();
  state->PopDrawFramebufferBinding();
  return this->Copy.Framebuffer;
}

//------------------------------------------------------------------------------
bool vtkOctreeCompositor::ReadDepth(
  vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height, std::vector<float>& depth)
{
  this->UseWindow(window);
  vtkOpenGLState* state = window->GetState();
  depth.assign(static_cast<std::size_t>(width) * height, 1.0f);
  GLint drawFramebuffer = 0, samples = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFramebuffer);
  glGetIntegerv(GL_SAMPLES, &samples);
  // A multisampled framebuffer cannot be read: its depth is resolved into
  // a single-sampled copy first.
  unsigned int source = static_cast<unsigned int>(drawFramebuffer);
  if (samples > 0)
  {
    source = this->CopyDepth(window, source, x0, y0, width, height);
    x0 = y0 = 0;
  }
  state->PushReadFramebufferBinding();
  state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, source);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(x0, y0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
  state->PopReadFramebufferBinding();
  if (glGetError() != GL_NO_ERROR)
  {
    std::fill(depth.begin(), depth.end(), 1.0f);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
// On the GPU throughout: the depth is copied into a depth texture (a blit),
// drawn as floats into a single-channel float texture (a depth format
// cannot be shared with CUDA; a read of depth as floats is a slow path in
// some drivers), which CUDA copies into linear device memory.
const float* vtkOctreeCompositor::ReadDepthToDevice(
  vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height, int device, std::string& error)
{
  this->UseWindow(window);
  vtkOpenGLState* state = window->GetState();
  GLint drawFramebuffer = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFramebuffer);
  this->CopyDepth(window, static_cast<unsigned int>(drawFramebuffer), x0, y0, width, height);

  if (!this->FloatDepth)
  {
    this->FloatDepth = vtkSmartPointer<vtkTextureObject>::New();
    this->FloatDepth->SetContext(window);
    this->WindowDepth = vtkSmartPointer<vtkTextureObject>::New();
    this->WindowDepth->SetContext(window);
  }
  if (!this->FloatDepthFramebuffer || static_cast<int>(this->FloatDepth->GetWidth()) != width ||
    static_cast<int>(this->FloatDepth->GetHeight()) != height)
  {
    this->Interop->Release(); // a registration does not survive new storage
    this->FloatDepth->Allocate2D(width, height, 1, VTK_FLOAT);
    this->FloatDepth->SetMinificationFilter(vtkTextureObject::Nearest);
    this->FloatDepth->SetMagnificationFilter(vtkTextureObject::Nearest);
    if (!this->FloatDepthFramebuffer)
    {
      glGenFramebuffers(1, &this->FloatDepthFramebuffer);
    }
    state->PushDrawFramebufferBinding();
    state->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->FloatDepthFramebuffer);
    glFramebufferTexture2D(
      GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, this->FloatDepth->GetHandle(), 0);
    state->PopDrawFramebufferBinding();
  }
  if (!this->DepthQuad)
  {
    std::string fs = vtkOpenGLRenderUtilities::GetFullScreenQuadFragmentShaderTemplate();
    vtkShaderProgram::Substitute(fs, "//VTK::FSQ::Decl", "uniform sampler2D octorayWindowDepth;\n");
    vtkShaderProgram::Substitute(
      fs, "//VTK::FSQ::Impl", "  gl_FragData[0] = vec4(texture(octorayWindowDepth, texCoord).r, 0.0, 0.0, 1.0);\n");
    this->DepthQuad.reset(new vtkOpenGLQuadHelper(window, nullptr, fs.c_str(), nullptr));
  }
  else
  {
    window->GetShaderCache()->ReadyShaderProgram(this->DepthQuad->Program);
  }
  if (!this->DepthQuad->Program)
  {
    error = "the depth shader did not compile";
    return nullptr;
  }
  this->WindowDepth->AssignToExistingTexture(this->Copy.Texture, GL_TEXTURE_2D);
  {
    vtkOpenGLState::ScopedglViewport viewport(state);
    vtkOpenGLState::ScopedglEnableDisable depthTest(state, GL_DEPTH_TEST);
    vtkOpenGLState::ScopedglEnableDisable blend(state, GL_BLEND);
    vtkOpenGLState::ScopedglEnableDisable scissor(state, GL_SCISSOR_TEST); // as in CopyDepth
    state->PushDrawFramebufferBinding();
    state->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, this->FloatDepthFramebuffer);
    state->vtkglViewport(0, 0, width, height);
    state->vtkglDisable(GL_DEPTH_TEST);
    state->vtkglDisable(GL_BLEND);
    state->vtkglDisable(GL_SCISSOR_TEST);
    this->WindowDepth->Activate();
    this->DepthQuad->Program->SetUniformi("octorayWindowDepth", this->WindowDepth->GetTextureUnit());
    this->DepthQuad->Render();
    this->WindowDepth->Deactivate();
    state->PopDrawFramebufferBinding();
  }
  if (glGetError() != GL_NO_ERROR)
  {
    error = "OpenGL could not copy the depth into a float texture";
    return nullptr;
  }
  return this->Interop->CopyToDevice(this->FloatDepth->GetHandle(), width, height, device, error);
}

//------------------------------------------------------------------------------
// Full float: the window depth must survive to 1e-4 and better, and the
// colour is blended before it is rounded to the framebuffer's bytes.
void vtkOctreeCompositor::AllocateTextures(int width, int height)
{
  if (!this->ColorTexture)
  {
    this->ColorTexture = vtkSmartPointer<vtkTextureObject>::New();
    this->DepthTexture = vtkSmartPointer<vtkTextureObject>::New();
    this->ColorTexture->SetContext(this->Window);
    this->DepthTexture->SetContext(this->Window);
  }
  if (this->ColorTexture->GetHandle() && static_cast<int>(this->ColorTexture->GetWidth()) == width &&
    static_cast<int>(this->ColorTexture->GetHeight()) == height)
  {
    return;
  }
  this->Interop->Release(); // registrations do not survive a new storage
  this->ColorTexture->Create2DFromRaw(width, height, 4, VTK_FLOAT, nullptr);
  this->DepthTexture->Create2DFromRaw(width, height, 1, VTK_FLOAT, nullptr);
  for (vtkTextureObject* t : { this->ColorTexture.Get(), this->DepthTexture.Get() })
  {
    t->SetMinificationFilter(vtkTextureObject::Nearest);
    t->SetMagnificationFilter(vtkTextureObject::Nearest);
    t->SetWrapS(vtkTextureObject::ClampToEdge);
    t->SetWrapT(vtkTextureObject::ClampToEdge);
  }
}

//------------------------------------------------------------------------------
void vtkOctreeCompositor::SetPictureFromHost(vtkOpenGLRenderWindow* window, const octoray::Image& image)
{
  this->UseWindow(window);
  this->AllocateTextures(image.width, image.height);
  window->GetState()->vtkglPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  const struct
  {
    vtkTextureObject* Texture;
    GLenum Format;
    const float* Pixels;
  } planes[2] = { { this->ColorTexture, GL_RGBA, image.rgba.data() },
    { this->DepthTexture, GL_RED, image.depth.data() } };
  for (const auto& plane : planes)
  {
    plane.Texture->Activate();
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, image.width, image.height, plane.Format, GL_FLOAT, plane.Pixels);
    plane.Texture->Deactivate();
  }
  this->PictureReady = true;
}

//------------------------------------------------------------------------------
bool vtkOctreeCompositor::SetPictureFromDevice(
  vtkOpenGLRenderWindow* window, const octoray::DeviceImage& image, std::string& error)
{
  this->UseWindow(window);
  this->AllocateTextures(image.width, image.height);
  this->PictureReady =
    this->Interop->Copy(this->ColorTexture->GetHandle(), this->DepthTexture->GetHandle(), image, error);
  return this->PictureReady;
}

//------------------------------------------------------------------------------
// 2^bits - 1 for the red channel of the framebuffer drawn into when it has
// fixed-point colour (8, 10, 16 bits), 0 for floating point.
static float ColorLevels()
{
  GLint framebuffer = 0, bits = 0, type = GL_UNSIGNED_NORMALIZED;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &framebuffer);
  const GLenum attachment = framebuffer == 0 ? GL_BACK_LEFT : GL_COLOR_ATTACHMENT0;
  glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, attachment, GL_FRAMEBUFFER_ATTACHMENT_RED_SIZE, &bits);
  glGetFramebufferAttachmentParameteriv(
    GL_DRAW_FRAMEBUFFER, attachment, GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &type);
  if (glGetError() != GL_NO_ERROR || type == GL_FLOAT || bits <= 0 || bits > 16)
  {
    return 0.0f;
  }
  return static_cast<float>((1 << bits) - 1);
}

//------------------------------------------------------------------------------
bool vtkOctreeCompositor::Draw(vtkOpenGLRenderWindow* window)
{
  this->UseWindow(window);
  if (!this->PictureReady)
  {
    return true;
  }
  if (!this->Quad)
  {
    std::string fs = vtkOpenGLRenderUtilities::GetFullScreenQuadFragmentShaderTemplate();
    vtkShaderProgram::Substitute(fs, "//VTK::FSQ::Decl",
      "uniform sampler2D octorayColor;\n"
      "uniform sampler2D octorayDepth;\n"
      "uniform float octorayLevels;\n");
    // Pixels no ray coloured leave colour and depth as they were. The colour
    // is rounded to the framebuffer's levels here, to nearest: drivers
    // convert float to 8 bits differently (NVIDIA's and Mesa's differ by
    // one in the last bit), and a picture must not depend on the driver.
    vtkShaderProgram::Substitute(fs, "//VTK::FSQ::Impl",
      "  vec4 c = texture(octorayColor, texCoord);\n"
      "  if (c.a <= 0.0) { discard; }\n"
      "  if (octorayLevels > 0.0) { c = floor(clamp(c, 0.0, 1.0) * octorayLevels + 0.5) / octorayLevels; }\n"
      "  gl_FragData[0] = c;\n"
      "  gl_FragDepth = texture(octorayDepth, texCoord).r;\n");
    this->Quad.reset(new vtkOpenGLQuadHelper(window, nullptr, fs.c_str(), nullptr));
  }
  else
  {
    window->GetShaderCache()->ReadyShaderProgram(this->Quad->Program);
  }
  if (!this->Quad->Program)
  {
    return false;
  }
  vtkOpenGLState* state = window->GetState();
  vtkOpenGLState::ScopedglEnableDisable depthTest(state, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable blend(state, GL_BLEND);
  vtkOpenGLState::ScopedglDepthFunc depthFunc(state);
  vtkOpenGLState::ScopedglDepthMask depthMask(state);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFunc(state);
  // The rays already stopped at the opaque depth, so every fragment is in
  // front of what is drawn: the depth test only serves to write the depth.
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthFunc(GL_ALWAYS);
  state->vtkglDepthMask(GL_TRUE);
  state->vtkglEnable(GL_BLEND);
  state->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  // Over, whatever equation a pass left (dual depth peeling leaves MAX).
  GLint equation[2] = { GL_FUNC_ADD, GL_FUNC_ADD };
  glGetIntegerv(GL_BLEND_EQUATION_RGB, &equation[0]);
  glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &equation[1]);
  state->vtkglBlendEquation(GL_FUNC_ADD);
  this->ColorTexture->Activate();
  this->DepthTexture->Activate();
  this->Quad->Program->SetUniformi("octorayColor", this->ColorTexture->GetTextureUnit());
  this->Quad->Program->SetUniformi("octorayDepth", this->DepthTexture->GetTextureUnit());
  this->Quad->Program->SetUniformf("octorayLevels", ColorLevels());
  this->Quad->Render();
  this->DepthTexture->Deactivate();
  this->ColorTexture->Deactivate();
  state->vtkglBlendEquationSeparate(static_cast<unsigned int>(equation[0]), static_cast<unsigned int>(equation[1]));
  return true;
}

//------------------------------------------------------------------------------
void vtkOctreeCompositor::ReleaseGraphicsResources(vtkWindow* window)
{
  auto* glWindow = vtkOpenGLRenderWindow::SafeDownCast(window);
  if (glWindow && (this->ColorTexture || this->Copy.Framebuffer || this->FloatDepth))
  {
    glWindow->MakeCurrent();
  }
  this->Interop->Release();
  if (this->ColorTexture)
  {
    this->ColorTexture->ReleaseGraphicsResources(window);
    this->DepthTexture->ReleaseGraphicsResources(window);
  }
  this->ColorTexture = nullptr;
  this->DepthTexture = nullptr;
  if (this->Quad)
  {
    this->Quad->ReleaseGraphicsResources(window);
    this->Quad.reset();
  }
  if (this->DepthQuad)
  {
    this->DepthQuad->ReleaseGraphicsResources(window);
    this->DepthQuad.reset();
  }
  if (this->FloatDepth)
  {
    this->FloatDepth->ReleaseGraphicsResources(window);
    this->WindowDepth->ReleaseGraphicsResources(window);
  }
  this->FloatDepth = nullptr;
  this->WindowDepth = nullptr;
  if (glWindow && this->FloatDepthFramebuffer)
  {
    glDeleteFramebuffers(1, &this->FloatDepthFramebuffer);
  }
  this->FloatDepthFramebuffer = 0;
  this->Copy.Release(glWindow != nullptr);
  this->PictureReady = false;
  this->Window = nullptr;
}
