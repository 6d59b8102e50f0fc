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
// A multisampled framebuffer cannot be read: its depth is blitted into a
// single-sampled one of the same format, whose name this returns (bound for
// reading, the viewport at its origin).
unsigned int vtkOctreeCompositor::ResolveDepth(
  vtkOpenGLRenderWindow* window, unsigned int drawFramebuffer, int width, int height)
{
  vtkOpenGLState* state = window->GetState();
  const unsigned int format = DepthFormat(drawFramebuffer);
  if (!this->ResolveFramebuffer || this->ResolveSize[0] != width || this->ResolveSize[1] != height ||
    this->ResolveFormat != format)
  {
    if (!this->ResolveFramebuffer)
    {
      glGenFramebuffers(1, &this->ResolveFramebuffer);
      glGenRenderbuffers(1, &this->ResolveRenderbuffer);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, this->ResolveRenderbuffer);
    glRenderbufferStorage(GL_RENDERBUFFER, format, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, this->ResolveFramebuffer);
    const bool withStencil = format == GL_DEPTH24_STENCIL8 || format == GL_DEPTH32F_STENCIL8;
    glFramebufferRenderbuffer(GL_READ_FRAMEBUFFER, withStencil ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT,
      GL_RENDERBUFFER, this->ResolveRenderbuffer);
    this->ResolveSize[0] = width;
    this->ResolveSize[1] = height;
    this->ResolveFormat = format;
  }
  return this->ResolveFramebuffer;
}

//------------------------------------------------------------------------------
// glReadPixels of the viewport's depth (as floats) from the framebuffer VTK
// draws into, resolved first when it is multisampled, into `pixels`: host
// memory, or an offset in the bound pixel-pack buffer.
bool vtkOctreeCompositor::ReadDepthInto(
  vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height, void* pixels)
{
  this->UseWindow(window);
  vtkOpenGLState* state = window->GetState();
  GLint drawFramebuffer = 0, samples = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFramebuffer);
  glGetIntegerv(GL_SAMPLES, &samples);

  state->PushReadFramebufferBinding();
  state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<unsigned int>(drawFramebuffer));
  if (samples > 0)
  {
    const unsigned int resolved = this->ResolveDepth(window, drawFramebuffer, width, height);
    state->PushDrawFramebufferBinding();
    state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<unsigned int>(drawFramebuffer));
    state->vtkglBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolved);
    glBlitFramebuffer(x0, y0, x0 + width, y0 + height, 0, 0, width, height, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
    state->PopDrawFramebufferBinding();
    state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, resolved);
    x0 = y0 = 0;
  }
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(x0, y0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, pixels);
  state->PopReadFramebufferBinding();
  return glGetError() == GL_NO_ERROR;
}

//------------------------------------------------------------------------------
bool vtkOctreeCompositor::ReadDepth(
  vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height, std::vector<float>& depth)
{
  depth.assign(static_cast<std::size_t>(width) * height, 1.0f);
  if (!this->ReadDepthInto(window, x0, y0, width, height, depth.data()))
  {
    std::fill(depth.begin(), depth.end(), 1.0f);
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
const float* vtkOctreeCompositor::ReadDepthToDevice(
  vtkOpenGLRenderWindow* window, int x0, int y0, int width, int height, int device, std::string& error)
{
  this->UseWindow(window);
  const std::size_t bytes = sizeof(float) * static_cast<std::size_t>(width) * height;
  if (!this->DepthPixelBuffer)
  {
    glGenBuffers(1, &this->DepthPixelBuffer);
  }
  glBindBuffer(GL_PIXEL_PACK_BUFFER, this->DepthPixelBuffer);
  if (this->DepthPixelBufferBytes != bytes)
  {
    this->Interop->Release(); // a registration does not survive new storage
    glBufferData(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_COPY);
    this->DepthPixelBufferBytes = bytes;
  }
  const bool read = this->ReadDepthInto(window, x0, y0, width, height, nullptr);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  if (!read)
  {
    error = "glReadPixels of the depth into a pixel buffer failed";
    return nullptr;
  }
  return static_cast<const float*>(this->Interop->MapBuffer(this->DepthPixelBuffer, bytes, device, error));
}

void vtkOctreeCompositor::ReleaseDeviceDepth()
{
  this->Interop->UnmapBuffer();
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
  this->ColorTexture->Activate();
  this->DepthTexture->Activate();
  this->Quad->Program->SetUniformi("octorayColor", this->ColorTexture->GetTextureUnit());
  this->Quad->Program->SetUniformi("octorayDepth", this->DepthTexture->GetTextureUnit());
  this->Quad->Program->SetUniformf("octorayLevels", ColorLevels());
  this->Quad->Render();
  this->DepthTexture->Deactivate();
  this->ColorTexture->Deactivate();
  return true;
}

//------------------------------------------------------------------------------
void vtkOctreeCompositor::ReleaseGraphicsResources(vtkWindow* window)
{
  auto* glWindow = vtkOpenGLRenderWindow::SafeDownCast(window);
  if (glWindow && (this->ColorTexture || this->ResolveFramebuffer || this->DepthPixelBuffer))
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
  if (this->ResolveFramebuffer && glWindow)
  {
    glDeleteFramebuffers(1, &this->ResolveFramebuffer);
    glDeleteRenderbuffers(1, &this->ResolveRenderbuffer);
  }
  if (this->DepthPixelBuffer && glWindow)
  {
    glDeleteBuffers(1, &this->DepthPixelBuffer);
  }
  this->DepthPixelBuffer = 0;
  this->DepthPixelBufferBytes = 0;
  this->ResolveFramebuffer = this->ResolveRenderbuffer = 0;
  this->ResolveSize[0] = this->ResolveSize[1] = 0;
  this->PictureReady = false;
  this->Window = nullptr;
}
