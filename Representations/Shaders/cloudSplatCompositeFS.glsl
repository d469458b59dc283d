// The cloud splats' composite (vtkNimbusCloudSplatMapper): the view pass's float target,
// the balls' premultiplied colour C and coverage A (002 §3.3's blending, summed in float),
// added to the frame once. Over the scene's own linear frame the blend does it
// (GL_ONE, GL_ONE_MINUS_SRC_ALPHA: frame (1 - A) + C); over a Nimbus sky, whose frame
// is sRGB-encoded (encodeSrgb), blending is off and the frame under the balls
// (sceneColor, a copy) is decoded, dimmed and added to in linear light and encoded again,
// as the cloud mapper composites over the sky.
//VTK::System::Dec
in vec2 texCoord;
uniform sampler2D splatSum;
uniform sampler2D sceneColor;
uniform int encodeSrgb;
//VTK::Output::Dec
//NIMBUS::Library

void main()
{
  vec4 sum = texture(splatSum, texCoord);
  if (sum.a <= 0.0 && max(sum.r, max(sum.g, sum.b)) <= 0.0)
  {
    discard;
  }
  sum.a = min(sum.a, 1.0);
  if (encodeSrgb == 1)
  {
    vec4 scene = texture(sceneColor, texCoord);
    vec3 linear = SrgbDecode(scene.rgb) * (1.0 - sum.a) + sum.rgb;
    gl_FragData[0] = vec4(SrgbEncode(clamp(linear, 0.0, 1.0)), scene.a + sum.a * (1.0 - scene.a));
    return;
  }
  gl_FragData[0] = sum;
}
