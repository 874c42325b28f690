use std::arch::x86_64::*;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};
#[derive(Clone, Copy)]
pub struct F8(pub __m512d);
impl F8 {
    #[inline(always)] pub fn splat(x: f64) -> Self { unsafe { F8(_mm512_set1_pd(x)) } }
    #[inline(always)] pub fn load(a: &[f64; 8]) -> Self { unsafe { F8(_mm512_loadu_pd(a.as_ptr())) } }
    #[inline(always)] pub fn store(self, a: &mut [f64; 8]) { unsafe { _mm512_storeu_pd(a.as_mut_ptr(), self.0) } }
    #[inline(always)] pub fn sqrt(self) -> Self { unsafe { F8(_mm512_sqrt_pd(self.0)) } }
    #[inline(always)] pub fn max(self, o: Self) -> Self { unsafe { F8(_mm512_max_pd(self.0, o.0)) } }
    /// self if lo < self < hi else `other`
    #[inline(always)] pub fn select_in(self, lo: f64, hi: f64, t: Self, f: Self) -> Self {
        unsafe {
            let m1 = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.0, _mm512_set1_pd(lo));
            let m2 = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(self.0, _mm512_set1_pd(hi));
            F8(_mm512_mask_blend_pd(m1 & m2, f.0, t.0))
        }
    }
}
impl F8 {
    /// self where lo < r2 < hi, else 0
    #[inline(always)] pub fn select_in_r2(self, r2: F8, lo: f64, hi: f64) -> Self {
        unsafe {
            let m1 = _mm512_cmp_pd_mask::<_CMP_GT_OQ>(r2.0, _mm512_set1_pd(lo));
            let m2 = _mm512_cmp_pd_mask::<_CMP_LT_OQ>(r2.0, _mm512_set1_pd(hi));
            F8(_mm512_maskz_mov_pd(m1 & m2, self.0))
        }
    }
}
impl Add for F8 { type Output = F8; #[inline(always)] fn add(self, o: F8) -> F8 { unsafe { F8(_mm512_add_pd(self.0, o.0)) } } }
impl Sub for F8 { type Output = F8; #[inline(always)] fn sub(self, o: F8) -> F8 { unsafe { F8(_mm512_sub_pd(self.0, o.0)) } } }
impl Mul for F8 { type Output = F8; #[inline(always)] fn mul(self, o: F8) -> F8 { unsafe { F8(_mm512_mul_pd(self.0, o.0)) } } }
impl Div for F8 { type Output = F8; #[inline(always)] fn div(self, o: F8) -> F8 { unsafe { F8(_mm512_div_pd(self.0, o.0)) } } }
impl Neg for F8 { type Output = F8; #[inline(always)] fn neg(self) -> F8 { F8::splat(0.0) - self } }
impl AddAssign for F8 { #[inline(always)] fn add_assign(&mut self, o: F8) { *self = *self + o } }
