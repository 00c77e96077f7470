! Modern Fortran through the mufric module (ISO_C_BINDING): one block of contact points with the
! standard deviation and a 95 % interval from a Gaussian-process model given as argument (URI).
! Checks that every output came through the binding consistently: lo < mu < hi and
! (hi - lo) / 2 = 1.959964 std for every point, and an out-of-box point flagged EXTRAPOLATED.
program module_example
  use, intrinsic :: iso_c_binding
  use mufric
  implicit none
  integer, parameter :: n = 4
  real(c_double), target :: p(n), v(n), t(n), mu(n), sd(n), lo(n), hi(n)
  integer(c_int), target :: status(n)
  type(c_ptr) :: client
  character(len=512) :: uri
  integer :: k, failures

  call get_command_argument(1, uri)
  if (mufric_connect(uri, client) /= MUFRIC_OK) then
    print *, 'mufric_connect: ', mufric_error()
    stop 2
  end if
  p = [500.0d6, 800.0d6, 1100.0d6, 2000.0d6]         ! Pa; the last is outside the training box
  v = [60.0d0, 100.0d0, 150.0d0, 100.0d0] / 60.0d0    ! m/s
  t = [300.0d0, 500.0d0, 700.0d0, 500.0d0] + 273.15d0 ! K
  if (c_mufric_evaluate(client, int(n, c_size_t), c_loc(p), c_loc(v), c_loc(t), c_null_ptr, 0.95d0, &
                        c_loc(mu), c_loc(sd), c_loc(lo), c_loc(hi), c_loc(status)) /= MUFRIC_OK) then
    print *, 'mufric_evaluate: ', mufric_error()
    stop 2
  end if
  failures = 0
  do k = 1, n
    print '(a, f8.1, a, f7.4, a, es9.2, a, f7.4, a, f7.4, a, i2)', 'p[MPa]', p(k) / 1.0d6, '  mu', mu(k), '  std', sd(k), &
          '  95% [', lo(k), ',', hi(k), ']  status', status(k)
    if (.not. (lo(k) < mu(k) .and. mu(k) < hi(k))) failures = failures + 1
    if (abs((hi(k) - lo(k)) / 2.0d0 - 1.959963984540054d0 * sd(k)) > 1.0d-12) failures = failures + 1
  end do
  if (any(status(1:3) /= MUFRIC_POINT_OK) .or. status(4) /= MUFRIC_POINT_EXTRAPOLATED) failures = failures + 1
  call c_mufric_close(client)
  if (failures > 0) then
    print *, failures, 'inconsistent outputs'
    stop 1
  end if
  print *, 'all outputs consistent'
end program
