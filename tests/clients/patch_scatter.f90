! The patch scatter through the Fortran module: a model trained by stochastic kriging on a dataset of
! independent draws serves it (finite and positive inside and outside the box, fill=-1 for a point
! without an answer), a model without one says so and refuses the call. Usage: SK_URI PLAIN_URI
program patch_scatter
  use, intrinsic :: iso_c_binding
  use mufric
  use client_checks
  implicit none
  integer, parameter :: n = 4
  real(c_double), target :: p(n), v(n), t(n), patch(n)
  integer(c_int), target :: status(n)
  integer(c_int) :: used(4)
  real(c_double) :: lo(4), hi(4)
  type(c_ptr) :: client
  character(len=1024) :: sk_uri, plain_uri

  call get_command_argument(1, sk_uri)
  call get_command_argument(2, plain_uri)
  if (mufric_connect(sk_uri, client, 'fill=-1') /= MUFRIC_OK) then
    write (0, *) 'mufric_connect: ', mufric_error()
    stop 1
  end if
  call check(c_mufric_has_patch_scatter(client) == 1, 'the stochastic-kriging model has a patch scatter')
  call check(c_mufric_box(client, used, lo, hi) == MUFRIC_OK, 'box')
  p = 0.5d0 * (lo(1) + hi(1))
  v = 0.5d0 * (lo(2) + hi(2))
  t = 0.5d0 * (lo(3) + hi(3))
  p(2) = 2d0 * hi(1)  ! outside: the nearest face's scatter
  t(3) = -1d0         ! no answer: the fill value
  if (c_mufric_patch_std(client, int(n, c_size_t), c_loc(p), c_loc(v), c_loc(t), c_null_ptr, c_loc(patch), &
                         c_loc(status)) /= MUFRIC_PARTIAL) then  ! point 3 has no answer
    write (0, *) 'mufric_patch_std: ', mufric_error()
    stop 1
  end if
  call check(patch(1) > 0d0 .and. patch(1) < 1d0, 'inside the box: a positive scatter')
  call check(patch(2) > 0d0 .and. status(2) == MUFRIC_POINT_EXTRAPOLATED, 'outside the box: the face''s scatter')
  call check(patch(3) == -1d0 .and. status(3) == MUFRIC_POINT_INVALID_INPUT, 'no answer: fill=-1')
  call check(patch(4) == patch(1), 'the same point, the same bits')
  call c_mufric_close(client)

  if (mufric_connect(plain_uri, client) /= MUFRIC_OK) then
    write (0, *) 'mufric_connect: ', mufric_error()
    stop 1
  end if
  call check(c_mufric_has_patch_scatter(client) == 0, 'a model trained on data without draws has none')
  call check(c_mufric_patch_std(client, 1_c_size_t, c_loc(p), c_loc(v), c_loc(t), c_null_ptr, c_loc(patch), &
                                c_null_ptr) == MUFRIC_INVALID_ARGUMENT, 'and refuses the call')
  call check(index(mufric_error(), 'no patch scatter') > 0, 'saying why: ' // mufric_error())
  call c_mufric_close(client)
  if (failures > 0) stop 1
  print '(a)', 'patch_scatter (Fortran): every check passed'

end program
