// The 11-tap SSIM window (loss_shared.h), unrolled by hand: no loop, no indexed local array (lavapipe
// spills those). TAP(k, w) must add w times the value at offset k along the pass's axis (0 outside the
// image: zero padding, as conv2d with padding 5).
#define SSIM_WINDOW(TAP)                                                                       \
  TAP(-5, SSIM_W5) TAP(-4, SSIM_W4) TAP(-3, SSIM_W3) TAP(-2, SSIM_W2) TAP(-1, SSIM_W1)         \
  TAP(0, SSIM_W0) TAP(1, SSIM_W1) TAP(2, SSIM_W2) TAP(3, SSIM_W3) TAP(4, SSIM_W4) TAP(5, SSIM_W5)
